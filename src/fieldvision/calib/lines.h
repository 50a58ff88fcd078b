// Pose refinement against the painted field lines. Line pixels: white, thin, on grass (a
// white top-hat in grey level with low saturation, inside the projected field area), thinned to
// the middles of their horizontal and vertical cross-sections. A top-view distance lookup table
// of the field model's line centrelines (exact point-to-segment/arc distances, 1 cell = 10 mm by
// default, the seed used 20 mm) is read through Ceres' bicubic interpolator; the pose is refined
// by minimising the distance of the line pixels' ground points to the nearest line (Ceres, Cauchy
// loss, coarse to fine): chamfer matching (Barrow et al., "Parametric correspondence and chamfer
// matching", IJCAI 1977) on the ground plane, as RoboCup teams match field lines against a
// distance table. Written by hand: OpenCV has no model-to-image line registration.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"

namespace ceres {
class Problem;
}  // namespace ceres

namespace fv::calib {

struct LineDetectOptions {
  double min_tophat = 25.0;      // grey levels brighter than the surroundings
  double max_saturation = 90.0;  // HSV saturation (0-255) of white
  // Widest line cross-section kept, in pixels; 0: from the camera, the field's line width and
  // the nearest visible line (2.5 x its projected width + 3 px).
  int max_width_px = 0;
  double field_margin_m = 0.5;  // keep pixels whose ground point is this far outside the field
  bool mask_goals = true;       // ignore the image area of the (white) goals
  int max_pixels = 20000;       // evenly subsampled beyond this
  void Check() const;
};

// Line pixels (centres of thin white cross-sections) of a BGR frame seen by `camera` (with a
// pose), outside the image area of the field's goals. Throws fv::Error when the image size differs
// from the camera's.
std::vector<Eigen::Vector2d> DetectLinePixels(const cv::Mat& image_bgr,
                                              const camera::Camera& camera,
                                              const field::FieldModel& field,
                                              const LineDetectOptions& options = {});

// Distance (metres) from points of the ground to the nearest line centreline, on a grid.
class LineDistanceMap {
 public:
  // Cells of `resolution_m` over the field and its surround (coarser if that would exceed
  // max_cells); distances beyond max_distance_m are clamped.
  explicit LineDistanceMap(const field::FieldModel& field, double resolution_m = 0.01,
                           double max_distance_m = 1.0, int max_cells = 8'000'000);
  double resolution_m() const { return resolution_m_; }
  double max_distance_m() const { return max_distance_m_; }
  // Bilinear lookup; max_distance_m outside the grid.
  double Distance(double x_m, double y_m) const;
  // For Ceres: grid coordinates of a ground point (row, column).
  template <typename T>
  void ToGrid(const T& x_m, const T& y_m, T* row, T* col) const {
    *col = (x_m - T(x0_m_)) / T(resolution_m_);
    *row = (y_m - T(y0_m_)) / T(resolution_m_);
  }
  const std::vector<float>& values() const { return values_; }
  int rows() const { return rows_; }
  int cols() const { return cols_; }

 private:
  double resolution_m_, max_distance_m_, x0_m_, y0_m_;
  int rows_, cols_;
  std::vector<float> values_;  // row-major, row = y
};

struct LineErrorStats {
  int num_pixels = 0;    // line pixels whose ground point is on the field
  int num_inliers = 0;   // within gate_m of a line
  double mean_mm = 0.0;  // over inliers
  double p95_mm = 0.0;
  double median_mm = 0.0;
  double gate_m = 0.0;
  // Over every line pixel given, each at most gate_m (a pixel off the field or above the
  // horizon counts gate_m): compares two poses on the same pixels (0 without pixels).
  double truncated_mean_mm = 0.0;
  std::string Summary() const;
};

// Line error of a pose: distance of the line pixels' ground points to the nearest line
// centreline (exact), over those within gate_m (the rest are other white things).
LineErrorStats LineError(const camera::Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                         const field::FieldModel& field, double gate_m = 0.5);

struct RefineOptions {
  LineDetectOptions detect;
  double lut_resolution_m = 0.01;
  double lut_max_distance_m = 1.0;
  // Cauchy loss scales of the successive stages (metres): wide to capture, narrow to finish.
  std::vector<double> loss_scales_m = {0.25, 0.08, 0.03};
  int max_iterations = 100;  // per stage
  double gate_m = 0.5;       // for the reported line error
  // A refined pose that moves the camera farther than this from the start is rejected.
  double max_move_m = 3.0;
  // Refine the rotation only, the camera's centre held where it is (a camera on a tripod that
  // turns: three unknowns instead of six, held by fewer lines).
  bool fix_centre = false;
  void Check() const;
};

struct RefineResult {
  camera::Camera camera;  // refined (or the input when rejected)
  bool accepted = false;
  std::string status;  // why not accepted
  LineErrorStats before, after;
  int num_line_pixels = 0;
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  double moved_m = 0.0;  // camera centre change
  double rotated_deg = 0.0;
  std::string Summary() const;
};

// Refines camera.cam_from_world (intrinsics fixed) so that the frame's line pixels fall on the
// field's lines. Throws fv::Error when the camera has no pose or the image is of another size
// than the camera; too few line pixels is a result with accepted = false.
RefineResult RefineWithLines(const camera::Camera& camera, const cv::Mat& image_bgr,
                             const field::FieldModel& field, const RefineOptions& options = {});
// The same on line pixels already detected.
RefineResult RefineWithLinePixels(const camera::Camera& camera,
                                  const std::vector<Eigen::Vector2d>& pixels,
                                  const field::FieldModel& field,
                                  const RefineOptions& options = {});
// The same with the field's distance table built once (a video's frames); the table's resolution
// and reach replace options.lut_resolution_m and lut_max_distance_m.
RefineResult RefineWithLinePixels(const camera::Camera& camera,
                                  const std::vector<Eigen::Vector2d>& pixels,
                                  const field::FieldModel& field, const LineDistanceMap& map,
                                  const RefineOptions& options = {});

// Throws fv::Error naming `field` when it has no painted lines (segments or arcs): both line
// refinements would report a line error of 0 mm over no pixels.
void RequirePaintedLines(const field::FieldModel& field);

// The pose solve of both line refinements (RefineWithLinePixels, RefineRigWithLines): `build`
// adds the residuals (on *rvec, *tvec) with a Cauchy loss of the given scale; the problem is
// solved at each of `scales` in turn, then its robust cost at the last scale is evaluated at the
// solution (final) and at the start pose (initial).
struct LossScaleSolve {
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
};
LossScaleSolve SolveOverLossScales(const std::function<void(ceres::Problem&, double)>& build,
                                   const std::vector<double>& scales, int max_iterations,
                                   Eigen::Vector3d* rvec, Eigen::Vector3d* tvec,
                                   const Eigen::Vector3d& rvec_start,
                                   const Eigen::Vector3d& tvec_start);

// The acceptance test of both line refinements: empty when the refined pose is taken, else why
// not (a camera moved more than max_move_m, naming `rig`'s start pose or the camera's; the robust
// cost did not fall).
std::string LineRefinementRefusal(double moved_m, double max_move_m, double initial_cost,
                                  double final_cost, bool rig);

// Checks that an image matches the camera's size; throws naming both.
void CheckImageSize(const cv::Mat& image, const camera::Camera& camera,
                    const std::string& image_name, const std::string& camera_name);

}  // namespace fv::calib
