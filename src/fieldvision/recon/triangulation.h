// Triangulation of the ball centre from 1..N calibrated cameras, one method a file
// (triangulation_*.cc): two rays (closest point), N views linear (DLT, Hartley & Zisserman 2nd ed.
// sec. 12.2) and refined (Ceres, covariance H&Z sec. 5.2), a robust search over the candidates
// (exhaustive RANSAC, Fischler & Bolles 1981) and one camera with the ball on the ground. With
// outline_centre the model predicts a blob's centre: (X Z, Y Z) / (Z^2 - r^2) in normalized
// coordinates (exact for the tangent cone).
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "fieldvision/camera/camera.h"
#include "fieldvision/geometry/rigid.h"

namespace fv::recon {

// One ball candidate seen by one camera (what a detector reports), in that camera's pixels.
struct BallObservation {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double radius_px = 0.0;  // 0 when unknown
  double sigma_px = 1.0;   // 1-sigma uncertainty of the centre
  double score = 1.0;      // detector confidence, higher is better
  // A candidate that failed a single-view shape check (detect/ball_detector.h): the robust mode
  // uses it only to complete a set that an accepted candidate of another camera starts, and only
  // when the accepted candidates alone give no 3D position.
  bool weak = false;
  // The share of its disc that differs from its camera's background (detect/background.h): near
  // 1 for a thing that came into view, near 0 for one that was always there; -1: not compared.
  double background_change = -1.0;
};

// ---- Two rays -----------------------------------------------------------------------------

enum class RayPairStatus { kOk, kParallel, kBehind };

struct RayPairResult {
  RayPairStatus status = RayPairStatus::kParallel;
  Eigen::Vector3d midpoint = Eigen::Vector3d::Zero();  // halfway between the closest points
  double gap_m = 0.0;                                  // distance between the two rays there
  double s_a = 0.0, s_b = 0.0;                         // ray parameters of the closest points
  double angle_deg = 0.0;                              // angle between the directions
  bool ok() const { return status == RayPairStatus::kOk; }
};

// The closest point of two rays (directions need not be unit length). Rays closer to parallel
// than `min_angle_deg` give kParallel; a closest point behind either origin gives kBehind (the
// midpoint is still filled in). Never throws for geometry; throws fv::Error for NaN input.
RayPairResult ClosestPointOfRays(const geometry::Ray3d& a, const geometry::Ray3d& b,
                                 double min_angle_deg = 0.01);

// ---- N views --------------------------------------------------------------------------------

struct TriangulationOptions {
  // Ball radius in metres: the ground height of single-camera positions, the size check and the
  // outline-centre model.
  double ball_radius_m = 0.11;
  // Observations are centres of the ball's outline (a blob's centre) rather than projections of
  // the sphere's centre (what a tangent-cone fit such as detect/ball_fit.h reports).
  bool outline_centre = false;
  // Nonlinear refinement of the linear estimate (Ceres, Levenberg-Marquardt).
  bool refine = true;
  int max_iterations = 25;
  // A view is consistent when its reprojection error is below
  // max(inlier_threshold_px, inlier_sigmas * sigma_px).
  double inlier_threshold_px = 4.0;
  double inlier_sigmas = 3.0;
  // Points nearer than this in front of a camera (or behind it) are rejected.
  double min_depth_m = 0.1;
  // Two-view hypotheses whose rays meet at less than this angle are degenerate.
  double min_angle_deg = 2.0;
  // Robust mode: the best `max_candidates_per_camera` blobs (by score) of each camera are tried.
  int max_candidates_per_camera = 6;
  // Reject points whose centre lies lower than a ball resting on the ground (ball_radius_m above
  // it) by more than this (metres) plus three standard deviations of the point's height: a low
  // orange object (a cone, a marker) is no ball, whatever the cameras agree on. Negative
  // disables the check.
  double max_below_rest_m = 0.015;
  // Where a ball centre can be (world frame, metres): a point outside this box is no ball,
  // whatever the cameras agree on (an advertising board behind the goal, a light above the
  // field); its candidates are dropped as for max_below_rest_m. Empty (the default): anywhere.
  // ball_job sets it to the field plus the detector's margin, up to its highest ball.
  Eigen::AlignedBox3d allowed_region;
  // When the detector reports radius_px: a view whose radius differs from the radius predicted
  // from the depth by more than this factor (either way) is inconsistent; 0 disables. Two
  // cameras' still objects of the ball's colour can meet at a point by chance; their sizes rarely
  // fit it (a circle on a shaded ball's lit part is at most about a third smaller). Measured on
  // the renders (`ball --truth`): low-sun static 12 of 16 frames, a ghost 16 m off -> 13 of 16, one
  // 4.3 m off; low-sun-kick mean 4.1 -> 3.2 mm; kick, held, fisheye unchanged (1.3: fisheye 15 ->
  // 12 of 16 frames).
  double max_radius_ratio = 1.5;
  // A view whose radius is more than this factor larger than the one predicted from the depth is
  // inconsistent too; 0: max_radius_ratio alone. Shading, occlusion and a print's fragments make
  // a fitted circle smaller, never larger: a larger one took in something beside the ball, and
  // its centre moved with it. Measured with `detect` on 13 renders (kick, low-sun kick and static
  // seeds 1-3, static seeds 1-3, three lighting variants): of 3302 accepted candidates on the
  // ball, fitted radius / true radius p99 1.14; 27 of the 31 above 1.15 had centres 0.5-6.5 px
  // off. `ball --truth` (1.25): low-sun static seed 3 7.42 -> 5.17 mm (a fragment 2.3 px off
  // with a radius 1.36x too large no longer pairs), seed 6 3.80 -> 3.66 mm, seed 5 one frame of
  // 16 less; 32 other renders unchanged (kicks, statics, fisheye, held, lighting variants).
  double max_larger_radius_ratio = 1.25;
  // Between sets of equally many cameras the higher total detector score wins; each view's
  // score counts weighted by how well its radius fits the set's point, exp(-0.5 (ln(radius /
  // radius predicted from the depth) / score_radius_sigma)^2), when the detector reports
  // radius_px; 0: the scores alone. A ball in the air is scored below a still ball-coloured thing
  // far beyond it (the detector prefers a ball's size on the ground), and pairing one camera's
  // ball with another's thing puts the point along the first camera's ray, where that camera's
  // radius no longer fits. Measured on the renders (`ball --truth`, low-sun static seeds 1-8, 16
  // frames each): points more than 0.5 m off 3 -> 1, frames found 123 -> 127 of 128 (sigma
  // 0.07, 0.1 and 0.15 alike; 0.2 keeps seed 3's ghost); static seeds 1-3, held, fisheye, kick,
  // low-sun kick seeds 1-3 unchanged. 0.15, the widest that works: a shaded ball measured 25 %
  // small still weighs 0.16 (0.02 at 0.1).
  double score_radius_sigma = 0.15;
  // A set of two cameras whose total radius-weighted score is below this is no ball unless it
  // lies within prior_gate_m of the prior: two faint, still things of the ball's colour in two
  // cameras (a yellow block on an advertising board, scored 0.06-0.18) meet somewhere by chance
  // when the ball itself is accepted by one camera only. The two-camera positions of the renders
  // (`ball --truth`, colour, low-sun static seeds 1-6, low-sun kick seeds 1-3, held, fisheye)
  // scored 0.21-1.62 where they were the ball (the faintest on the kicks, near the prior) and
  // 0.03-0.14 where they were such a ghost. At 0.2: static seeds 1 / 3 ghosts 3 / 1 -> 0 (seed 1
  // 16 of 16 frames placed, the three frames on the ball instead), seeds 9 / 10 (rendered after
  // the choice) 1 / 1 -> 0, seed 10 one frame more; nothing else changed (0.15-0.25 remove the
  // same ghosts; 0.3 loses a frame of the ball on seed 1), `--detector both` unchanged. 0: off
  // (`ball --detections`: scores made elsewhere have no known scale).
  double min_two_view_score = 0.2;
  // Two cameras alone, one seeing a thing that came into view (its disc differs from that
  // camera's background on at least new_min_change of it) and the other a thing that was there
  // all along (at most still_max_change), are no ball: one ball is new, or still, in every camera
  // at once. A ball-coloured board in the stands of one camera met the ray of a flying ball that
  // the other camera saw (the low-sun static render, seed 10: a position 1.9 m off). Only views
  // whose detector compared them with a background (BallObservation::background_change) count.
  // still_max_change 0: off.
  double still_max_change = 0.1;
  double new_min_change = 0.7;
  // Robust mode: with only one camera seeing anything, place the ball on the ground.
  bool single_camera_ground = false;
  // Robust mode: use weak candidates (BallObservation::weak) when the others give no position.
  bool use_weak = true;
  // A weak view whose radius differs from the one predicted from the depth by more than this
  // factor (either way) is inconsistent (when the detector reports radius_px).
  double weak_max_radius_ratio = 1.5;
  // A set of weak views only is kept when at least this many cameras agree (0: never) and the
  // point lies within prior_gate_m of the prior (the ball's predicted position; no prior, no
  // such set): a static ball-like object (a cone) seen by every camera is consistent too.
  int min_views_all_weak = 3;
  double prior_gate_m = 1.0;
  // With a prior, a two-view hypothesis farther than prior_gate_m from it is no ball (it cannot
  // have jumped there): a static ball-like object elsewhere that more cameras agree on never
  // takes a tracked ball's place (pipeline/fusion_stage.h's predictor forgets a track after a
  // few frames without a position, so a ball lost longer is searched everywhere again). false:
  // the prior only admits sets of weak views. Gating a track's measurements by its prediction,
  // as in Bar-Shalom & Fortmann, "Tracking and Data Association" (1988).
  bool gate_by_prior = true;
  // Unless nothing lies within prior_gate_m of the prior and at least this many cameras agree on
  // a point elsewhere: the ball did move there (a hard kick at a low frame rate, a ball put down
  // anew), as a static ghost seen by that many cameras is rare (and fusion's hover filter drops
  // it). 0: never.
  int prior_override_views = 3;
  // When the detector reports radius_px: a view whose radius differs from the one expected at the
  // refined point by more than radius_tolerance (a share of the expected radius) plus
  // radius_tolerance_px has the rest (times radius_sigma_factor) added to its centre's sigma and
  // the point is refined again. A circle fitted to part of the ball (its lit side, its shaded
  // side lost against the background) is smaller and its centre off by about as much; 0: off.
  // The tolerance is the fitted radius' own noise (0.1-0.3 px on the renders; the depth's error
  // adds well under 1 %): measured on the renders at libjpeg 90 (`ball --truth`, mean error of
  // the positions within 0.5 m) against 10 % + 0.5 px: low-sun static seeds 1-3 colour 3.69 /
  // 3.99 / 4.99 -> 2.95 / 3.14 / 4.85 mm, `both` 3.72 / 3.99 / 7.82 -> 3.18 / 3.13 / 7.64, seeds
  // 4-6 (not looked at before) colour 4.01 / 4.17 / 4.25 -> 3.09 / 4.07 / 3.91, `both` 3.36 /
  // 4.29 / 3.31 -> 3.07 / 4.07 / 3.49; held 4.19 -> 3.63; low-sun kick seeds 1-3 1.21 / 1.45 /
  // 1.38 -> 1.21 / 1.36 / 1.43; fisheye 8.32 -> 8.38; kick unchanged (0.15 and 0.5 px alike).
  double radius_sigma_factor = 1.0;
  double radius_tolerance = 0.0;
  double radius_tolerance_px = 0.3;

  void Check() const;  // throws fv::Error naming the bad field
};

enum class TriangulationStatus {
  kOk,               // a 3D point (or a ground point when `on_ground`)
  kTooFewViews,      // fewer than 2 views (and no ground mode)
  kDegenerate,       // rays (nearly) parallel or the linear system is singular
  kBehindCamera,     // the point lies behind (or too close to) a camera
  kNoConsistentSet,  // robust mode: no two cameras agree
};

const char* ToString(TriangulationStatus status);

struct ViewResidual {
  int camera = -1;     // index into the camera list
  int candidate = -1;  // index into that camera's candidates (robust mode), else 0
  Eigen::Vector2d residual_px = Eigen::Vector2d::Zero();  // predicted - observed
  double err_px = 0.0;                                    // |residual_px|
};

struct TriangulationResult {
  TriangulationStatus status = TriangulationStatus::kTooFewViews;
  Eigen::Vector3d point_world = Eigen::Vector3d::Zero();
  // Covariance of point_world in m^2 from the weighted Jacobian, (J^T J)^-1; for a ground
  // point the z row and column are zero.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  bool on_ground = false;  // single camera, centre assumed at z = ball radius: a 2D position
  std::vector<ViewResidual> views;  // the views used, in camera order
  double rms_px = 0.0;              // RMS of err_px over `views`
  int iterations = 0;               // Ceres iterations of the final refinement
  int hypotheses = 0;               // robust mode: two-view hypotheses scored
  int weak_views = 0;               // robust mode: views from weak candidates
  // Robust mode: the points of the consistent two-view hypotheses (every view within three
  // standard deviations), the chosen one's among them, each with its 1-sigma size from the rays'
  // geometry; they tell a caller where ball-coloured things stand (pipeline/fusion_stage.h).
  struct Alternative {
    Eigen::Vector3d point_world = Eigen::Vector3d::Zero();
    double sigma_m = 0.0;
  };
  std::vector<Alternative> alternatives;
  bool ok() const { return status == TriangulationStatus::kOk; }
  int num_views() const { return static_cast<int>(views.size()); }
};

// A view used by TriangulatePoint: which camera saw the ball where.
struct View {
  int camera = 0;  // index into the camera list
  BallObservation observation;
};

// Linear triangulation only (weighted DLT on undistorted normalized points). nullopt when fewer
// than two views, a pixel cannot be undistorted or the solution is at infinity.
std::optional<Eigen::Vector3d> TriangulateLinear(const std::vector<camera::Camera>& cameras,
                                                 const std::vector<View>& views);

// All views together: DLT, refinement, residuals and covariance. No outlier rejection (see
// TriangulateRobust). Throws fv::Error for a camera index out of range, a camera without a pose
// or a non-finite observation.
TriangulationResult TriangulatePoint(const std::vector<camera::Camera>& cameras,
                                     const std::vector<View>& views,
                                     const TriangulationOptions& options = {});

// Robust mode: candidates[c] are camera c's blobs (any number, possibly none). Scores every
// two-view hypothesis, keeps the one with the most consistent cameras (then the smallest
// weighted error), refines it on those views and returns it. Weak candidates are tried only
// when the others give no 3D position, in sets with at least one candidate that is not weak or
// with at least min_views_all_weak cameras. Throws fv::Error when
// candidates.size() != cameras.size().
// `prior`: where the ball is expected (e.g. extrapolated from the last frames), or null.
TriangulationResult TriangulateRobust(const std::vector<camera::Camera>& cameras,
                                      const std::vector<std::vector<BallObservation>>& candidates,
                                      const TriangulationOptions& options = {},
                                      const Eigen::Vector3d* prior = nullptr);

// One camera, the ball resting on the ground (centre at z = options.ball_radius_m): intersects
// the ray with that plane and refines x, y. Status kBehindCamera when the ray does not reach the
// plane in front of the camera.
TriangulationResult LocateOnGround(const camera::Camera& camera, int camera_index,
                                   const BallObservation& observation,
                                   const TriangulationOptions& options = {});

// The model's prediction of where `camera` sees the ball centred at `point_world` (the outline's
// centre when radius_m > 0); nullopt when the point is not in front of the camera.
std::optional<Eigen::Vector2d> PredictBallCentre(const camera::Camera& camera,
                                                 const Eigen::Vector3d& point_world,
                                                 double radius_m);

}  // namespace fv::recon
