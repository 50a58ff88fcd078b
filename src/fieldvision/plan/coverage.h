// Coverage of a field by a camera rig: on a grid of ball positions (at the ball's resting height
// and optionally higher), which cameras see each point (in front, inside the image, the ball at
// least `min_ball_px` wide), the camera pair whose rays meet closest to 90 degrees, and the
// expected 3D error of the ball from Gaussian pixel noise propagated to first order through the
// least-squares triangulation of all cameras that see it: Cov = (sum_i J_i^T J_i / sigma^2)^-1
// with J_i the Jacobian of camera i's projection (Hartley & Zisserman, Multiple View Geometry,
// 2nd ed., sec. 5.2 and 12.2).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"

namespace fv::plan {

struct CoverageOptions {
  double grid_step_m = 0.1;        // grid cell size (cells are equal, centred in the area)
  bool include_surround = false;   // grid over the playing area plus the run-off area
  double ball_diameter_m = 0.22;   // FIFA size 5 (football, RoboCup MSL); layer 0 is its radius
  double height_above_m = 1.0;     // a second layer this far above the first; 0: none
  double min_ball_px = 5.0;        // the ball must be at least this wide in the image; 0: no limit
  double margin_px = 0.0;          // the ball's centre must be this far inside the image border
  double pixel_noise_px = 1.0;     // detection noise (standard deviation per image axis)
  double good_angle_min_deg = 40;  // pair angles in [min, max] triangulate well
  double good_angle_max_deg = 120;
  double error_weight_per_m = 1.0;  // score = good fraction - weight * worst expected error
  bool progress = false;            // show progress on stderr

  // Throws fv::Error naming the bad field.
  void Check() const;
};

// One horizontal grid of points; cell (i, j) has its centre at (x0 + i step_x, y0 + j step_y).
struct CoverageLayer {
  double height_m = 0;
  int nx = 0, ny = 0;
  double x0_m = 0, y0_m = 0, step_x_m = 0, step_y_m = 0;
  std::vector<int> count;              // cameras seeing each cell, index j * nx + i
  std::vector<double> best_angle_deg;  // NaN where fewer than 2 cameras see it
  std::vector<double> err_rms_m;       // sqrt(trace Cov); NaN where it cannot be triangulated
  std::vector<double> err_max_axis_m;  // sqrt(largest eigenvalue of Cov)

  // Statistics over the cells.
  std::vector<double> fraction_exactly;  // k = 0 .. number of cameras
  double fraction_at_least_2 = 0;
  double fraction_good = 0;               // >= 2 cameras and best angle in the good range
  double angle_median_deg = NAN;          // over cells seen by >= 2 cameras
  double fraction_angle_good_of_2 = NAN;  // share of the >= 2 cells whose best angle is good
  double err_median_m = NAN;              // over good cells
  double err_p95_m = NAN;
  double err_max_m = NAN;  // the worst expected error over good cells
  double err_max_axis_max_m = NAN;
  double score = 0;  // fraction_good - error_weight_per_m * err_max_m

  Eigen::Vector3d CellCentre(int i, int j) const {
    return {x0_m + i * step_x_m, y0_m + j * step_y_m, height_m};
  }
  size_t size() const { return count.size(); }
};

struct CoverageResult {
  CoverageOptions options;  // the options it was computed with
  int num_cameras = 0;
  std::vector<CoverageLayer> layers;  // layer 0 at the ball's height
  double seconds = 0;
  // The rig's score: the mean of its layers' (the ball on the ground and in the air), so that
  // a search never trades the air for the ground.
  double score() const;
  // A table: per layer the fractions by camera count, angles and errors.
  std::string Summary() const;
};

// Whether `camera` sees a ball centred at `p_world` (see CoverageOptions).
bool SeesPoint(const camera::Camera& camera, const Eigen::Vector3d& p_world,
               const CoverageOptions& options);
// Angle at `p_world` between the rays to the two camera centres, degrees in [0, 180].
double RayAngleDeg(const Eigen::Vector3d& centre_a, const Eigen::Vector3d& centre_b,
                   const Eigen::Vector3d& p_world);
// Jacobian d(pixel)/d(p_world) of the camera's projection (distortion included); nullopt behind.
std::optional<Eigen::Matrix<double, 2, 3>> ProjectionJacobian(const camera::Camera& camera,
                                                              const Eigen::Vector3d& p_world);
// First-order covariance of the point triangulated from `cameras` with isotropic pixel noise
// sigma_px; nullopt when the rays do not determine the point (one camera, parallel rays).
std::optional<Eigen::Matrix3d> TriangulationCovariance(
    const std::vector<const camera::Camera*>& cameras, const Eigen::Vector3d& p_world,
    double sigma_px);

// Throws fv::Error (naming the step and the field) when the grid would have over 4 million cells.
// `what` names the step in the error (a job names its option).
void CheckCoverageGrid(const field::FieldModel& field, const CoverageOptions& options,
                       std::string_view what = "grid step");

CoverageResult EvaluateCoverage(const std::vector<camera::Camera>& cameras,
                                const field::FieldModel& field, const CoverageOptions& options);

}  // namespace fv::plan
