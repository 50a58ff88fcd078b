// Ball flights from a 3D ball track: splits the track into airborne arcs at ground contacts,
// kicks and hits (velocity jumps that gravity cannot explain, found by comparing gravity-only fits
// of the samples before and after each gap), and fits each arc with a point-mass model under known
// gravity and optional quadratic air drag, a = g - k |v| v (Ceres, Huber loss; drag model as in
// R. Cross, "Physics of Baseball & Softball", 2011, ch. 6). Also fits the seed's plane quadratic
// (three last points, then least squares) for comparison.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace fv {

// One 3D ball position (a row of BALL.csv).
struct BallSample {
  long long frame = -1;  // -1 when the file has no frame numbers
  double time_s = 0.0;
  Eigen::Vector3d ball_in_world = Eigen::Vector3d::Zero();
  int n_cams = 0;
  double err_px = 0.0;
};

// Point-mass flight: position p0 and velocity v0 at t0_s, gravity along -z, acceleration
// g - k |v| v with k = drag_per_m (0: a parabola).
struct BallisticModel {
  double t0_s = 0.0;
  Eigen::Vector3d p0_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v0_mps = Eigen::Vector3d::Zero();
  double gravity_mps2 = 9.81;
  double drag_per_m = 0.0;

  Eigen::Vector3d PositionAt(double time_s) const;
  Eigen::Vector3d VelocityAt(double time_s) const;
  void StateAt(double time_s, Eigen::Vector3d* p_m, Eigen::Vector3d* v_mps) const;
  // The first time after (forward) or before (!forward) `from_s` where the centre height crosses
  // z_m, searched up to max_s away; nullopt if none.
  std::optional<double> CrossingTime(double z_m, double from_s, bool forward,
                                     double max_s = 10.0) const;
};

// Result of fitting one model to the samples of a flight.
struct BallisticFit {
  BallisticModel model;
  bool ok = false;
  double rmse_m = 0.0;  // over the inliers
  int inliers = 0;
  int iterations = 0;        // Ceres iterations
  std::vector<bool> inlier;  // per sample given to the fit
};

// The seed's method: a quadratic z(s) in the vertical plane of the flight (s: horizontal distance),
// started from the last three points and refined by least squares over all of them; time is a
// linear function of s.
struct PlaneQuadraticFit {
  bool ok = false;
  std::string failure;  // why not ok (e.g. "vertical flight")
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d landing_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d apex_m = Eigen::Vector3d::Zero();
  double t_origin_s = 0.0, t_landing_s = 0.0;
  double gravity_mps2 = 0.0;  // implied by the curvature and the horizontal speed
  double rmse_m = 0.0;
};

enum class DragMode { kOff, kOn, kAuto };
// "off", "on", "auto"; throws naming `context` otherwise.
DragMode ParseDragMode(const std::string& s, const std::string& context);
const char* DragModeName(DragMode m);

struct TrajectoryOptions {
  double gravity_mps2 = 9.81;       // along -z
  double ball_radius_m = 0.11;      // size-5 football; origin and landing have z = ground + radius
  double ground_z_m = 0.0;          // height of the surface the ball bounces on
  DragMode drag = DragMode::kAuto;  // auto: use drag when it lowers the residual by > 10 %
  double noise_m = 0.0;             // position noise (1 sigma); 0: estimated from the track
  double window_s = 0.1;            // span of the local fits that look for breaks and outliers
  int window_samples = 3;           // fewest samples on each side of a break
  double min_velocity_change_mps = 1.0;  // smaller velocity jumps are never breaks
  double break_sigmas = 6.0;             // a break needs a jump this many standard errors large
  // plus this unmodelled acceleration (drag, spin) times half the span of the two local fits
  double unmodelled_accel_mps2 = 10.0;
  double outlier_sigmas = 5.0;       // a sample this far from both local fits is an outlier
  double min_outlier_m = 0.03;       // and at least this far
  double ground_tolerance_m = 0.03;  // centre within radius + this (+3 noise) counts as on ground
  double min_ground_s = 0.1;         // a ground phase (rolling, at rest) lasts at least this
  double max_gap_s = 0.5;            // longer gaps without samples end a flight
  int min_flight_samples = 4;        // shorter arcs are reported as unfitted hops
  double max_drag_per_m = 2.0;       // upper bound of k
  int max_iterations = 50;

  void Check() const;
};

// How an arc starts or ends.
enum class FlightEvent { kBounce, kGround, kHit, kTrackStart, kTrackEnd };
const char* FlightEventName(FlightEvent e);

struct Flight {
  int index = 0;
  std::vector<int> samples;  // indices into the track (inliers and outliers of this arc)
  FlightEvent start_event = FlightEvent::kTrackStart;
  FlightEvent end_event = FlightEvent::kTrackEnd;
  double t_start_s = 0.0;  // contact (or hit) that starts the arc
  double t_end_s = 0.0;    // contact or hit that ends it
  double t_first_seen_s = 0.0, t_last_seen_s = 0.0;
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();   // ball centre at t_start_s
  Eigen::Vector3d landing_m = Eigen::Vector3d::Zero();  // centre where the arc meets the ground
  double t_landing_s = 0.0;
  bool origin_extrapolated = false;   // t_start_s lies outside the seen samples' span
  bool landing_extrapolated = false;  // the arc was not seen to land (hit, end of track)
  Eigen::Vector3d apex_m = Eigen::Vector3d::Zero();
  double t_apex_s = 0.0;
  Eigen::Vector3d v0_mps = Eigen::Vector3d::Zero();  // at t_start_s
  double speed_mps = 0.0;                            // |v0|
  double rmse_m = 0.0;                               // of the chosen model
  bool drag_used = false;
  BallisticFit no_drag, with_drag;  // with_drag.ok is false when it was not fitted
  PlaneQuadraticFit seed;
  const BallisticModel& model() const { return drag_used ? with_drag.model : no_drag.model; }
  double FlightTime() const { return t_end_s - t_start_s; }
};

// A velocity jump between two arcs (for the timeline and the pictures).
struct TrackBreak {
  double time_s = 0.0;
  Eigen::Vector3d ball_in_world = Eigen::Vector3d::Zero();
  double velocity_change_mps = 0.0;
  FlightEvent kind = FlightEvent::kHit;
};

struct TrajectoryResult {
  std::vector<Flight> flights;     // in time order
  std::vector<TrackBreak> breaks;  // bounces and hits found between arcs
  std::vector<bool> outlier;       // per track sample
  std::vector<bool> on_ground;     // per track sample: rolling or at rest
  double noise_m = 0.0;            // used (given or estimated)
  int short_hops = 0;              // arcs with too few samples to fit
  std::string Summary() const;
};

// Robust noise estimate (1 sigma, metres) from second differences of gravity-corrected positions.
double EstimateTrackNoise(const std::vector<BallSample>& track, double gravity_mps2);

// Fits a ballistic model to samples (time order); drag is fitted when `fit_drag`. Huber loss at
// 3 sigma; samples farther than max(outlier_sigmas sigma, min_outlier_m) are outliers.
BallisticFit FitBallistic(const std::vector<BallSample>& samples, bool fit_drag,
                          const TrajectoryOptions& options, double noise_m);
PlaneQuadraticFit FitPlaneQuadratic(const std::vector<BallSample>& samples,
                                    const TrajectoryOptions& options);

// Splits a time-ordered track into flights and fits them.
TrajectoryResult AnalyzeTrajectory(const std::vector<BallSample>& track,
                                   const TrajectoryOptions& options);

}  // namespace fv
