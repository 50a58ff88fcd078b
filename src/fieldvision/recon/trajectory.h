// Ball flights from a 3D ball track: splits the track into airborne arcs at ground contacts,
// kicks and hits (velocity jumps that gravity cannot explain, found by comparing gravity-only fits
// of the samples before and after each gap), and fits each arc with a point-mass model under known
// gravity, optional quadratic air drag and optional Magnus lift from a constant spin,
// a = g - k |v| v + c_M w x v (Ceres, Huber loss; drag and Magnus models as in R. Cross, "Physics
// of Baseball & Softball", 2011, ch. 6-7). The spin model is kept when it lowers the Bayesian
// information criterion (Schwarz 1978) by a clear margin. Also fits a free constant-acceleration
// model and the seed's plane quadratic (three last points, then least squares) for comparison.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace fv::recon {

// One 3D ball position (a row of BALL.csv).
struct BallSample {
  long long frame = -1;  // -1 when the file has no frame numbers
  double time_s = 0.0;
  Eigen::Vector3d ball_in_world = Eigen::Vector3d::Zero();
  int n_cams = 0;
  double err_px = 0.0;
};

// Point-mass flight: position p0 and velocity v0 at t0_s, gravity along -z, acceleration
// g - k |v| v + c_M w x v with k = drag_per_m, w = spin_radps (constant) and c_M = magnus_per_rad
// (both 0: a parabola).
struct BallisticModel {
  double t0_s = 0.0;
  Eigen::Vector3d p0_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v0_mps = Eigen::Vector3d::Zero();
  double gravity_mps2 = 9.81;
  double drag_per_m = 0.0;
  Eigen::Vector3d spin_radps = Eigen::Vector3d::Zero();  // angular velocity (right hand), rad/s
  double magnus_per_rad = 0.0;  // c_M: Magnus acceleration per (rad/s x m/s)

  bool Parabola() const { return drag_per_m == 0.0 && !HasSpin(); }
  bool HasSpin() const { return magnus_per_rad != 0.0 && !spin_radps.isZero(); }
  // The spin in revolutions per second (its norm) and its unit axis (right hand).
  double SpinRevPerS() const;

  Eigen::Vector3d PositionAt(double time_s) const;
  Eigen::Vector3d VelocityAt(double time_s) const;
  void StateAt(double time_s, Eigen::Vector3d* p_m, Eigen::Vector3d* v_mps) const;
  // Moves a state of this model (position, velocity at some time) on by dt_s (either sign).
  void Advance(double dt_s, Eigen::Vector3d* p_m, Eigen::Vector3d* v_mps) const;
  // Positions at increasing times, each integrated from the one before (O(span), where
  // PositionAt per time integrates from t0_s each time); a parabola's in closed form.
  std::vector<Eigen::Vector3d> PositionsAt(const std::vector<double>& times_s) const;
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
  int iterations = 0;  // Ceres iterations
  // Work of the drag and spin models' residuals: paths integrated through all samples (one per
  // evaluation at new parameters) and RK4 steps in all (trajectory_path.h).
  long long path_sweeps = 0, path_steps = 0;
  std::vector<bool> inlier;  // per sample given to the fit
  int parameters = 0;        // free parameters (6 gravity, 7 drag, 10 spin)
  // Sum of squared residuals with each sample's residual capped at the outlier threshold of the
  // track's noise (the same cap for every model of a flight), and the Bayesian information
  // criterion from it over the 3 n coordinates: 3n ln(sse / 3n) + parameters ln(3n).
  double capped_sse_m2 = 0.0;
  double bic = 0.0;
};

// Free constant-acceleration fit p(t) = p0 + v0 t + a t^2 / 2 (9 parameters, linear least
// squares): the reference a physical model should come close to over a short arc.
struct ConstantAccelerationFit {
  bool ok = false;
  double t0_s = 0.0;
  Eigen::Vector3d p0_m = Eigen::Vector3d::Zero(), v0_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
  double rmse_m = 0.0;
  Eigen::Vector3d PositionAt(double time_s) const;
  // The first time after from_s where the height descends through z_m; nullopt if none.
  std::optional<double> DescendingCrossing(double z_m, double from_s) const;
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
using SpinMode = DragMode;  // off, on, auto as for drag

// The models a flight is fitted with, each containing the one before.
enum class FlightModel { kGravity, kDrag, kSpin };
const char* FlightModelName(FlightModel m);

// A bounce on a horizontal surface (R. Cross, Am. J. Phys. 70(5), 2002; the sliding/rolling
// model of Nakashima et al., 2010): the normal velocity reverses with restitution e; a friction
// impulse (coefficient mu, times the normal impulse) opposes the contact point's velocity
// v_t + w x (-r z) and stops at rolling. Hollow ball (table tennis) I = 2/3 m r^2; solid 2/5.
struct BounceModel {
  double restitution = 0.9;
  double friction = 0.25;
  double inertia_factor = 2.0 / 3.0;  // I / (m r^2)
  void Check() const;
  // Velocity and spin after the bounce of a ball of radius_m.
  void Apply(double radius_m, Eigen::Vector3d* v_mps, Eigen::Vector3d* spin_radps) const;
};

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
  // (or, at a track end, is window_samples samples moving up or down slower than this)
  double max_resting_vz_mps = 0.3;
  double max_gap_s = 0.5;       // longer gaps without samples end a flight
  int min_flight_samples = 4;   // shorter arcs are reported as unfitted hops
  double max_drag_per_m = 2.0;  // upper bound of k
  int max_iterations = 50;
  // Spin (Magnus lift). auto: fitted on flights with >= spin_min_samples samples over
  // >= spin_min_span_s, kept when its BIC is lower than the drag (or gravity) model's by
  // spin_min_bic_gain (10: "very strong" evidence, Kass & Raftery 1995).
  SpinMode spin = SpinMode::kAuto;
  int spin_min_samples = 12;
  double spin_min_span_s = 0.12;
  double spin_min_bic_gain = 10.0;
  // Magnus coefficient c_M = lift_slope rho pi r^3 / (2 m): the lift coefficient taken as
  // C_L = lift_slope * S with the spin parameter S = r |w| / |v| (Cross 2011, ch. 7; about 1 for
  // smooth balls at S < 0.4). Only c_M w is measured: the spin in rev/s scales with 1 / lift_slope.
  double ball_mass_kg = 0.43;  // size-5 football; 0.0027 for a table-tennis ball
  double air_density_kgpm3 = 1.2;
  double lift_slope = 1.0;
  // Zero-mean prior on the spin (1 sigma, rev/s; it weighs as much as one sample off by the
  // noise): weak across the flight; tighter along it, where spin makes almost no force (a
  // rifle spin is told from sidespin only by the slow turn of the velocity) and is rare.
  double spin_prior_revps = 300.0;
  double spin_along_prior_revps = 5.0;
  double MagnusPerRad() const;
  BounceModel bounce;  // for predicting the flight after a bounce
  // Called with (arcs fitted, arcs in all) as each arc's drag and spin fits end (the arcs are
  // fitted on all threads; calls come one at a time); empty: none.
  std::function<void(size_t done, size_t total)> progress;

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
  bool spin_used = false;              // the chosen model is with_spin (drag and Magnus)
  BallisticFit no_drag, with_drag;     // with_drag.ok is false when it was not fitted
  BallisticFit with_spin;              // ok is false when it was not fitted
  ConstantAccelerationFit free_accel;  // for comparison
  PlaneQuadraticFit seed;
  FlightModel model_kind() const {
    return spin_used ? FlightModel::kSpin : drag_used ? FlightModel::kDrag : FlightModel::kGravity;
  }
  const BallisticModel& model() const {
    return spin_used ? with_spin.model : drag_used ? with_drag.model : no_drag.model;
  }
  double FlightTime() const { return t_end_s - t_start_s; }
};

// Restitution and friction measured at one bounce from the velocities (and spins) on both sides;
// ok is false when the ball does not approach the surface or the tangential change says nothing.
struct BounceFit {
  bool ok = false;
  double restitution = 0.0;
  double friction = 0.0;  // NaN-free: 0 when no sliding was seen
  Eigen::Vector3d spin_before_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d spin_after_radps = Eigen::Vector3d::Zero();
};
BounceFit FitBounce(const Eigen::Vector3d& v_before_mps, const Eigen::Vector3d& spin_before_radps,
                    const Eigen::Vector3d& v_after_mps, double radius_m,
                    double inertia_factor = 2.0 / 3.0);

// A velocity jump between two arcs (for the timeline and the pictures).
struct TrackBreak {
  double time_s = 0.0;
  Eigen::Vector3d ball_in_world = Eigen::Vector3d::Zero();
  double velocity_change_mps = 0.0;
  FlightEvent kind = FlightEvent::kHit;
  BounceFit bounce;  // kBounce with both arcs fitted: what the bounce did
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
// The same for any model, started from `start` when given: kSpin from the drag fit, say, and kDrag
// from the gravity fit of the same samples (what a cold kDrag fit computes first: the same result).
BallisticFit FitBallistic(const std::vector<BallSample>& samples, FlightModel kind,
                          const TrajectoryOptions& options, double noise_m,
                          const BallisticModel* start = nullptr);
ConstantAccelerationFit FitConstantAcceleration(const std::vector<BallSample>& samples);
PlaneQuadraticFit FitPlaneQuadratic(const std::vector<BallSample>& samples,
                                    const TrajectoryOptions& options);

// Splits a time-ordered track into flights and fits them.
TrajectoryResult AnalyzeTrajectory(const std::vector<BallSample>& track,
                                   const TrajectoryOptions& options);

}  // namespace fv::recon
