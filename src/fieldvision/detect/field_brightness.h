// Whether a candidate is as bright as a ball lying in the light that falls on the field: a
// RoboCup or FIFA ball (orange, yellow, white) reflects more than grass or carpet, so the lit
// part of its disc (its 90th percentile of V = max(R, G, B)) is at least as bright as the
// field's median V; an orange LED glowing on a dark robot, a robot's orange part, a shirt in
// the stands or a logo are darker. The field's brightness comes from the colour spec's "field"
// class over a grid of the image region; nothing is decided without enough field pixels.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/detect/colour.h"
#include "fieldvision/detect/image_field.h"

namespace fv::detect {

struct FieldBrightnessOptions {
  int step_px = 4;                // grid of the field's samples
  double min_field_share = 0.02;  // field share of the samples needed for a field brightness
  int min_field_samples = 50;
  int max_disc_samples = 2000;  // a large disc is read on a grid of about this many pixels
  // Where the colour spec's field class finds too little field: the image's own field colour.
  ImageFieldOptions image_field;
  // Throws fv::Error naming the bad field.
  void Check() const;
};

// The median V of the field-class pixels (`field_bit` of `table`, 0: none) on the grid over `roi`
// (the whole image when empty), else of the image's own field colour; a negative value when too
// few of them are field.
double FieldValue(const cv::Mat& bgr, const ColourTable& table, uint8_t field_bit,
                  const FieldBrightnessOptions& options = {}, const cv::Rect& roi = cv::Rect());

// The 90th percentile of V over the disc (centre, radius; at least the pixel under the centre),
// clipped to the image; a negative value when the disc lies outside it.
double LitValue(const cv::Mat& bgr, const Eigen::Vector2d& centre_px, double radius_px,
                const FieldBrightnessOptions& options = {});

}  // namespace fv::detect
