// Reading the Pose2Sim demo's reference calibration (a Qualisys .qca.txt export: per camera the
// pose as camera position in mm and orientation, intrinsics in sensor units of 1/64 px) into
// fv::camera::Camera, and frame-independent comparisons of two calibrations of the same rig:
// distances between camera centres and relative rotations between cameras, plus the residuals of
// the best rigid alignment of the centres (Kabsch/Umeyama without scale). Used by the real-data
// tests and `calibrate rig`-style reports.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"

namespace fv::calib {

// Cameras of a Qualisys calibration export (Calib.qca.txt), converted to OpenCV conventions as
// Pose2Sim does (the transform's rows are Qualisys' camera axes, looking along -z with y up: x_cam
// = Rx(pi) R (x - position)). Throws fv::Error naming the file when it cannot be read or has no
// cameras.
// A camera whose fov_video is all zeros (not in the capture) is left out and named in `skipped`
// (when given).
std::vector<camera::Camera> ReadQualisysCalibration(const std::string& path,
                                                    std::vector<std::string>* skipped = nullptr);

struct RigComparison {
  // Per pair (i < j): |C_i - C_j| of a minus that of b (mm), and the angle of
  // (R_i R_j^T)_a relative to (R_i R_j^T)_b (degrees).
  struct Pair {
    int i = 0, j = 0;
    double baseline_a_mm = 0, baseline_b_mm = 0, baseline_diff_mm = 0;
    double relative_rotation_diff_deg = 0;
  };
  std::vector<Pair> pairs;
  // Camera centres of a rigidly aligned onto those of b: residual per camera (mm).
  std::vector<double> aligned_centre_err_mm;
  double max_baseline_diff_mm = 0, max_rotation_diff_deg = 0, rms_aligned_err_mm = 0;
  std::string Summary() const;
};

// Both lists in the same camera order, all with poses; throws when sizes differ or < 2.
RigComparison CompareRigs(const std::vector<camera::Camera>& a,
                          const std::vector<camera::Camera>& b);

}  // namespace fv::calib
