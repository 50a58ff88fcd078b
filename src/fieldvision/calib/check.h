// Calibration check: the field model drawn over a frame through the camera (lines, arcs, goals'
// feet and keypoints, with the detected line pixels coloured by their distance to the model),
// the line error in mm, and optionally the per-point error table of known points (pixels and
// millimetres on the field), as the seed's check printed.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/calib/extrinsics.h"
#include "fieldvision/calib/lines.h"

namespace fv::calib {

struct CheckOptions {
  LineDetectOptions detect;
  double gate_m = 0.5;                                // line pixels farther off are not counted
  cv::Scalar model_colour = cv::Scalar(255, 0, 255);  // BGR: the projected model
  int thickness_px = 2;
  double sample_step_m = 0.1;  // spacing of drawn points along lines
  bool draw_line_pixels = true;
  void Check() const;
};

struct CheckResult {
  cv::Mat overlay;  // BGR frame with the model drawn over it
  LineErrorStats lines;
  std::vector<PointResidual> points;  // empty without known points
  std::string Summary() const;
};

// Projects the field's lines into `image` (BGR) through `camera` (with a pose).
void DrawFieldOverlay(cv::Mat& image, const camera::Camera& camera, const field::FieldModel& field,
                      const cv::Scalar& colour, int thickness_px = 2, double step_m = 0.1);

// Throws fv::Error when the camera has no pose or the frame's size differs from the camera's.
CheckResult CheckCalibration(const camera::Camera& camera, const cv::Mat& image_bgr,
                             const field::FieldModel& field,
                             const std::vector<PointCorrespondence>& known_points,
                             const CheckOptions& options = {});

// The error table: name,u,v,x_m,y_m,z_m,u_proj,v_proj,err_px,err_mm.
void WritePointErrorTable(const std::string& path, const std::vector<PointResidual>& points);

}  // namespace fv::calib
