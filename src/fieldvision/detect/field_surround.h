// Whether a spot lies on the field: the share of a ring just around it that is field (the colour
// spec's "field" class or the image's own field colour, image_field.h; not the lines' white,
// which a board or a robot's top shares). A ball of a few pixels has no outline to judge; without
// a posed camera what vouches for it is the carpet or grass around it, where an LED on a robot, a
// mark on a board or a light in the stands is framed by other colours.
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/detect/colour.h"
#include "fieldvision/detect/image_field.h"

namespace fv::detect {

struct FieldSurroundOptions {
  // The ring starts gap_px beyond the spot's radius and is width_px wide (a small ball's JPEG
  // and blur halo lies in the gap).
  double gap_px = 2.0;
  double width_px = 3.0;
  // A spot is on the field when at least this share of the ring's pixels (inside the image) is
  // field; 0 turns the check off.
  double min_share = 0.5;
  // Throws fv::Error naming the bad field.
  void Check() const;
};

// The field share of the ring around (centre_px, radius_px): pixels of `field_bits` in `table`,
// or held by `image_field` (may be null), among the ring's pixels in `roi` (empty: the image;
// nothing outside it is read). Negative when none of the ring lies there.
double FieldShareAround(const cv::Mat& bgr, const ColourTable& table, uint8_t field_bits,
                        const ImageFieldColour* image_field, const Eigen::Vector2d& centre_px,
                        double radius_px, const FieldSurroundOptions& options = {},
                        const cv::Rect& roi = cv::Rect());

}  // namespace fv::detect
