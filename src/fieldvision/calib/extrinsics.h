// Camera pose from points of known world position: RANSAC PnP (OpenCV's solvePnPRansac with
// AP3P minimal sets, and SQPnP on all points; G. Terzakis and M. Lourakis, "A consistently fast
// and globally optimal solution to the perspective-n-point problem", ECCV 2020) followed by a
// Levenberg-Marquardt refinement of the inliers with Ceres through the camera's templated model
// (camera/projection.h). Residuals are reported per point in pixels and in millimetres on the
// field (the clicked pixel back-projected onto the point's horizontal plane).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"

namespace fv::calib {

// One clicked pixel and the world point it shows.
struct PointCorrespondence {
  std::string name;  // keypoint name or "row N"
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
};

// Throws fv::Error naming `where` when the clicked pixel `uv_px` lies more than a pixel outside
// a `width` x `height` image (pixel centres at integers; nothing checked for a size of 0), and
// says so when it would lie inside with width and height swapped.
void RequireInImage(const Eigen::Vector2d& uv_px, int width, int height, const std::string& where);

// Reads POINTS.csv: a header and columns u,v,x,y,z (metres) or u,v,name (a keypoint of
// `field`). Throws fv::Error naming the file and line for a missing column, a bad number, an
// unknown keypoint name (or names when no field is given) or, with an image size, a point
// outside the image (RequireInImage).
std::vector<PointCorrespondence> ReadPointsCsv(const std::string& path,
                                               const field::FieldModel* field, int width = 0,
                                               int height = 0);

struct ExtrinsicsOptions {
  double ransac_threshold_px = 8.0;  // inlier threshold of RANSAC
  int ransac_iterations = 1000;
  double ransac_confidence = 0.999;
  int min_points = 4;  // fewer points is an error
  // Points whose spread off their best-fitting line is below this (metres) are "on one line".
  double min_line_spread_m = 0.02;
  bool refine = true;        // Ceres refinement of the inliers
  int max_iterations = 100;  // of the refinement

  void Check() const;
};

struct PointResidual {
  std::string name;
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  Eigen::Vector2d projected_px = Eigen::Vector2d::Zero();
  double err_px = 0.0;
  // Distance on the point's horizontal plane between the point and where the clicked pixel's ray
  // meets that plane; nullopt when the ray does not meet it in front of the camera.
  std::optional<double> err_mm;
  bool inlier = true;
};

struct ExtrinsicsResult {
  camera::Camera camera;  // the input intrinsics with the estimated pose
  std::vector<PointResidual> points;
  int num_inliers = 0;
  double rms_px = 0.0;       // over inliers
  double max_err_px = 0.0;   // over inliers
  double mean_err_mm = 0.0;  // over inliers with err_mm
  double max_err_mm = 0.0;
  int iterations = 0;  // of the refinement
  Eigen::Vector3d camera_position_m = Eigen::Vector3d::Zero();
  std::string Summary() const;
};

// Throws fv::Error when there are fewer than min_points points, the world points are all on one
// line, or no pose puts 4 points within the RANSAC threshold.
ExtrinsicsResult EstimatePose(const camera::Camera& intrinsics,
                              const std::vector<PointCorrespondence>& points,
                              const ExtrinsicsOptions& options = {});

// Residuals of `points` for a camera with a pose (used by EstimatePose and `calibrate check`).
std::vector<PointResidual> PointResiduals(const camera::Camera& camera,
                                          const std::vector<PointCorrespondence>& points);

}  // namespace fv::calib
