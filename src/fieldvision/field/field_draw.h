// Top views of a field: the mapping between field metres and image pixels (x right, y up), and
// drawing of lines, goals, hoops and keypoints. Heat maps, coverage maps and trajectories draw
// on the same canvas.
#pragma once

#include <string>
#include <vector>

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

// Axis ticks: 1, 2 or 5 times a power of ten, about eight over `range`.
double NiceStep(double range);
// `v` rounded to a multiple of `step`, without the "-0" of a rounded negative zero.
double TickValue(double v, double step);

// `text` broken into lines no wider than `width_px` in OpenCV's Hershey simplex font at
// `font_scale` (thickness 1): at spaces, and a word too long for a line (a file's path) after its
// '/' or, failing that, between characters.
std::vector<std::string> WrapText(const std::string& text, int width_px, double font_scale);

// Pixels FrameTopView adds left and right of the view (a view for an image `w` wide overall is
// ForField(field, w - kTopViewFrameWidthPx)), and where the view lies in the framed image.
inline constexpr int kTopViewFrameWidthPx = 80;
inline constexpr int kTopViewFrameLeftPx = 60;
inline constexpr int kTopViewFrameTopPx = 30;

// `image`, a top view drawn with `view`, framed on white with axes in metres (ticks along x below
// and y on the left, "x (m)", "y (m)"), a scale bar and `caption` under it (empty: no caption
// line).
cv::Mat FrameTopView(const cv::Mat& image, const TopView& view, const std::string& caption);

}  // namespace fv::field
