// Calibration of a camera without a board session (a coach's phone) from field points in one
// frame: the focal length (fx = fy, principal point at the image centre) and optionally the
// radial k1, together with the pose. Starts: RANSAC PnP (extrinsics.h) at a sweep of fields of
// view; the best is refined by Ceres over (f, k1, rvec, tvec), and the uncertainty comes from the
// Jacobian at the solution (ceres::Covariance, scaled by the residual variance), propagated to
// the camera position. For flat fields where a pose cannot be trusted, the image-ground
// homography alone (cv::findHomography, RANSAC, then Levenberg-Marquardt) with its errors in
// pixels and on the field. References: Hartley and Zisserman, "Multiple View Geometry", ch. 5
// (covariance) and 8.8 (calibration from one view).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "fieldvision/calib/extrinsics.h"
#include "fieldvision/camera/camera.h"

namespace fv::calib {

struct FocalOptions {
  bool estimate_k1 = false;  // also the radial k1 (needs points near the image edges)
  // Horizontal fields of view tried as starts (log-spaced).
  double min_hfov_deg = 15.0, max_hfov_deg = 130.0;
  int hfov_steps = 24;
  ExtrinsicsOptions pnp;
  double outlier_px = 8.0;  // points farther off after the fit are left out (then refitted)
  int min_points = 6;
  int max_iterations = 200;
  // Above this relative standard deviation of f the result carries a warning.
  double max_focal_rel_std = 0.05;
  void Check() const;
};

struct FocalResult {
  camera::Camera camera;  // fx = fy = f, principal point at the centre, distortion {k1, 0, 0, 0, 0}
  std::vector<PointResidual> points;
  int num_inliers = 0;
  double rms_px = 0.0;
  double hfov_deg = 0.0;
  Eigen::Vector3d camera_position_m = Eigen::Vector3d::Zero();
  // One standard deviation (from the covariance; NaN when the fit is degenerate).
  double std_focal_px = 0.0, std_k1 = 0.0, std_hfov_deg = 0.0;
  Eigen::Vector3d std_position_m = Eigen::Vector3d::Zero();
  double residual_sigma_px = 0.0;  // noise estimated from the residuals
  bool covariance_ok = false;
  std::vector<std::string> warnings;
  std::string Summary() const;
};

// Throws fv::Error for fewer than min_points points, points on one line or no fitting start.
FocalResult EstimateFocalAndPose(int width, int height,
                                 const std::vector<PointCorrespondence>& points,
                                 const FocalOptions& options = {});

struct HomographyResult {
  int width = 0, height = 0;
  Eigen::Matrix3d image_from_ground = Eigen::Matrix3d::Identity();  // (x, y, 1) m -> pixels
  std::vector<PointResidual> points;  // err_px in the image, err_mm on the ground
  int num_inliers = 0;
  double rms_px = 0.0, rms_mm = 0.0;
  std::string Summary() const;
};

// The ground homography from points on the ground (z = 0; others are an error naming them).
HomographyResult EstimateGroundHomography(int width, int height,
                                          const std::vector<PointCorrespondence>& points,
                                          double ransac_px = 8.0);
// OpenCV YAML with image_width, image_height, homography_image_from_ground and its inverse, and
// the fit's rms; written to a temporary file, then renamed.
void WriteHomographyYaml(const HomographyResult& h, const std::string& path);

}  // namespace fv::calib
