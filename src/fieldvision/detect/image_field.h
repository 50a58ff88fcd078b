// The field's own colour in an image whose field the colour spec's "field" class does not find (a
// teal, grey or olive carpet; a camera's white balance): the most common CIELAB colour of the
// region's lower part (a camera that sees the field sees mostly field there), taken as the field
// when at least min_share of those samples lie near it: within max_delta_l in lightness and
// max_delta_ab in chroma (light varies a carpet's lightness across it far more than its chroma).
// Used by the field boundary and the field brightness where the class has too little field.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace fv::detect {

struct ImageFieldOptions {
  bool enabled = true;
  double lower_share = 1.0 / 3.0;  // the region's lower part that is sampled
  int samples = 20000;             // about this many pixels of it are sampled (a grid)
  double min_share = 0.4;          // samples near the most common colour for a field colour
  // OpenCV's 8-bit CIELAB: L * 255 / 100; a, b in their own units (+128).
  double max_delta_l = 50.0;
  double max_delta_ab = 7.0;
  // Throws fv::Error naming the bad field.
  void Check() const;
};

struct ImageFieldColour {
  cv::Vec3f lab;  // OpenCV 8-bit CIELAB
  double max_delta_l = 50.0;
  double max_delta_ab = 7.0;
  bool Holds(const cv::Vec3b& lab_pixel) const;
};

// The field colour of `roi` (the whole image when empty) of a BGR image, or nullopt.
std::optional<ImageFieldColour> FindImageFieldColour(const cv::Mat& bgr, const cv::Rect& roi,
                                                     const ImageFieldOptions& options = {});

// The CIELAB (8-bit) of the pixels (xs[i], ys[j]) of a BGR image: a ys.size() x xs.size() image.
cv::Mat LabAt(const cv::Mat& bgr, const std::vector<int>& xs, const std::vector<int>& ys);

}  // namespace fv::detect
