// Intrinsic calibration from board views: Zhang's method as implemented by OpenCV's
// cv::calibrateCamera (Z. Zhang, "A flexible new technique for camera calibration", PAMI 2000),
// with the chosen distortion model, per-view reprojection errors, outlier views dropped (and
// named) before a final fit, a coverage report of the image area the corners reached, and
// warnings when the views do not constrain the model (few views, poor coverage, little tilt,
// large parameter standard deviations).
#pragma once

#include <string>
#include <vector>

#include "fieldvision/calib/board.h"
#include "fieldvision/camera/camera.h"

namespace fv::calib {

// Throws fv::Error unless n is an OpenCV distortion model size: 4, 5, 8, 12 or 14.
void CheckDistortionModel(int n);

// K3Model::kAuto keeps k3 where the evidence for it is very strong: a BIC gain (util::BicGain)
// over 10 (Kass and Raftery, "Bayes factors", JASA 1995). Corner errors of real boards are not
// independent, which inflates the gain: on the four real cameras of shared/data/pose2sim-4cam
// (boards reaching 53-63 % of the half diagonal) the one with a gain of 3.5 got k3 3.5 and a
// radial distortion at the image's corner 168 px from the Qualisys reference's.
inline constexpr double kK3MinBicGain = 10.0;
// The share of the corners, outermost from the image's centre, held out to report how each
// model extrapolates (IntrinsicsResult::k3_outer_rms_*).
inline constexpr double kK3HoldOutShare = 0.2;

// Optional distortion terms (k3; a rig camera's p1 p2): chosen by the views, always fitted, or
// zero.
enum class TermModel { kAuto, kFree, kZero };
// "auto", "free" or "zero" (any case); throws fv::Error naming `what` and the value otherwise.
TermModel ParseTermModel(const std::string& name, const std::string& what);
// The r^6 radial term k3 of the 5-coefficient model.
using K3Model = TermModel;
inline K3Model ParseK3Model(const std::string& name) { return ParseTermModel(name, "k3 model"); }

struct IntrinsicsOptions {
  BoardSpec board;
  DetectOptions detect;
  ImageSourceOptions source;
  // Distortion coefficients to estimate: 4 (k1 k2 p1 p2), 5 (+k3, OpenCV's default), 8 (rational
  // k4..k6), 12 (+ thin prism s1..s4) or 14 (+ tilted sensor tauX tauY).
  int num_distortion = 5;
  // k3 with 5 coefficients. kAuto fits without k3, then with it on the same views, and keeps it
  // only on very strong evidence (util::BicGain over the corners' residuals > kK3MinBicGain);
  // kFree (OpenCV's) always fits it; kZero leaves it out. kAuto and kFree both fit the other
  // model too and report how far apart the two put the image's corners (beyond the corners the
  // board reached, the model extrapolates) and how each predicts the outermost corners from the
  // others. Real lenses (shared/data/pose2sim-4cam, boards reaching 53-63 % of the half diagonal,
  // against the Qualisys reference): the radial displacement at the image's corner is off by
  // 0.4-19 px with kAuto (k3 left out on all four), 0.8-168 px with kFree. Projected views
  // (intrinsics tests): a lens without k3 seen by 12 views to about 75 % of the half diagonal,
  // image corners' error median 12.8 px, 161 at worst with kFree, 2.9 and 13.2 with kAuto; lenses
  // with k3 = +-0.05..0.1 seen by 16 views kept off the corners, kAuto's is 1.7-2.7 times kFree's
  // (median 5.4-9.8 px against 2.9-4.4, 12 seeds). Views reaching the corners help both.
  K3Model k3 = K3Model::kAuto;
  bool fix_aspect_ratio = false;     // fx = fy (CALIB_FIX_ASPECT_RATIO)
  bool zero_tangent = false;         // p1 = p2 = 0
  bool fix_principal_point = false;  // principal point at the image centre
  // A view is dropped when its RMS error exceeds both outlier_factor x the median view RMS and
  // outlier_min_px; then the camera is fitted again without it (at most max_drop_fraction of
  // the views are dropped).
  double outlier_factor = 4.0;
  double outlier_min_px = 1.5;
  double max_drop_fraction = 0.3;
  int min_views = 3;      // fewer usable views is an error
  int coverage_grid = 4;  // coverage report: grid cells per side
  // Focal-length check: the fit is redone with the focal length held this factor lower and
  // higher; when either still reaches an RMS under (1 + focal_profile_min_gain) x the fit's, the
  // views do not pin the focal length down (a warning).
  double focal_profile_factor = 1.25;
  double focal_profile_min_gain = 0.5;
  bool progress = true;     // progress on stderr while detecting corners
  std::string camera_name;  // written to the camera file

  void Check() const;
};

struct ViewReport {
  std::string name;
  bool board_found = false;
  int num_corners = 0;
  double rms_px = 0.0;  // reprojection RMS of this view in the final fit (or when dropped)
  bool used = false;
  std::string dropped_because;  // empty when used or when the board was not found
};

struct CoverageReport {
  int grid = 4;
  std::vector<int> corners_per_cell;  // row-major grid x grid
  double cell_fraction = 0.0;         // share of cells with at least one corner
  double radius_fraction = 0.0;       // farthest corner from the centre / half diagonal
  double tilt_range_deg = 0.0;        // spread of the board normals' angle to the optical axis
  std::string Describe() const;       // a small text map of the grid
};

struct IntrinsicsResult {
  camera::Camera camera;  // intrinsics only (has_pose = false), rms_px and notes set
  double rms_px = 0.0;    // OpenCV's RMS over all corners of the used views
  int num_images = 0;
  int num_found = 0;
  int num_used = 0;
  int fits = 0;  // calibrateCamera runs (1 + refits after dropping views)
  std::vector<ViewReport> views;
  CoverageReport coverage;
  // Standard deviations of fx, fy, cx, cy in pixels (from OpenCV's covariance estimate).
  double std_fx_px = 0, std_fy_px = 0, std_cx_px = 0, std_cy_px = 0;
  // The RMS (px) of the fit redone with the focal length held focal_profile_factor times lower
  // and higher (all else refitted): views that pin the focal length down pay for moving it; near
  // fronto-parallel views do not, whatever the covariance estimate says.
  double rms_focal_lower_px = 0.0, rms_focal_higher_px = 0.0;
  // With 5 coefficients and k3 free or auto (else k3_tested false): the RMS without and with k3,
  // the BIC gain of fitting it, whether the camera has it, and how far apart the two fits put the
  // image's corners.
  bool k3_tested = false, k3_kept = false;
  double rms_without_k3_px = 0.0, rms_with_k3_px = 0.0, k3_bic_gain = 0.0;
  // Both models fitted on the corners nearer the image's centre predict the outermost
  // kK3HoldOutShare of them: RMS px without and with k3 (infinity when not testable).
  double k3_outer_rms_without_px = 0.0, k3_outer_rms_with_px = 0.0;
  double k3_corner_shift_px = 0.0;
  std::vector<std::string> warnings;
  std::string Summary() const;
};

// Detects the board in every image of `images` (see ImageSource) and calibrates. Throws
// fv::Error naming the input when no image shows the board, images differ in size or fewer than
// min_views views are usable.
IntrinsicsResult CalibrateIntrinsics(const std::string& images, const IntrinsicsOptions& options);

// How far apart two lens models of one image size put the image's corners: each corner through
// `a` back to its ray (camera::Camera::Undistort), then through `b` into the image; px, the
// largest of the four; infinity when `a` cannot invert a corner (beyond where its model folds).
double CornerShiftPx(const camera::Camera& a, const camera::Camera& b);

// The fit alone, on views already detected (all of one size); used by the above and the tests.
IntrinsicsResult CalibrateFromViews(const std::vector<BoardView>& views,
                                    const IntrinsicsOptions& options);

}  // namespace fv::calib
