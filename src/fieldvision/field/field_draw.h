// Top views of a field: the mapping between field metres and image pixels (x right, y up), and
// drawing of lines, goals, hoops and keypoints. Heat maps, coverage maps and trajectories draw
// on the same canvas.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/field/field.h"

namespace fv::field {

struct TopView {
  double px_per_m = 20.0;
  double x_min_m = 0.0;  // field coordinates of the image's left edge
  double y_max_m = 0.0;  // and of its top edge
  cv::Size size;

  // A view of the field plus its surround, `width_px` wide.
  static TopView ForField(const FieldModel& field, int width_px, double extra_margin_m = 0.0);
  cv::Point2d ToPixel(const Eigen::Vector2d& p_m) const {
    return {(p_m.x() - x_min_m) * px_per_m, (y_max_m - p_m.y()) * px_per_m};
  }
  Eigen::Vector2d ToField(const cv::Point2d& px) const {
    return {x_min_m + px.x / px_per_m, y_max_m - px.y / px_per_m};
  }
};

struct FieldDrawOptions {
  cv::Scalar background = cv::Scalar(60, 130, 60);  // BGR
  cv::Scalar line_colour = cv::Scalar(255, 255, 255);
  bool keypoints = false;       // draw keypoints
  bool keypoint_names = false;  // and their names
  bool surround = true;         // shade the run-off area differently
};

// Draws the field's lines (and goals/hoops) onto `image`, which uses `view`.
void DrawFieldLines(cv::Mat& image, const FieldModel& field, const TopView& view,
                    const cv::Scalar& colour, int thickness_px = 0);
// A new BGR image of the field.
cv::Mat DrawField(const FieldModel& field, const TopView& view,
                  const FieldDrawOptions& options = {});

}  // namespace fv::field
