#include "fieldvision/recon/trajectory.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <set>

#include <ceres/ceres.h>
#include <fmt/format.h>
#include <Eigen/Dense>

#include "fieldvision/recon/trajectory_path.h"
#include "fieldvision/recon/trajectory_physics.h"
#include "fieldvision/recon/trajectory_stages.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/parallel.h"
#include "fieldvision/util/stats.h"

namespace fv::recon {
namespace {

// How far (3D) a sample must lie from an arc to be off it: outlier_sigmas noise sigmas in each
// axis, at least min_outlier_m.
double OffArcM(const TrajectoryOptions& o, double noise_m) {
  return std::max(o.min_outlier_m, o.outlier_sigmas * noise_m * std::sqrt(3.0));
}

// The top of the ground band: a ball centre at most this high is on the ground (resting height
// plus ground_tolerance_m and 3 noise sigmas).
double GroundBandTopM(const TrajectoryOptions& o, double noise_m) {
  return o.ground_z_m + o.ball_radius_m + o.ground_tolerance_m + 3 * noise_m;
}

// The model's Magnus vector s = c_M w.
Eigen::Vector3d MagnusVector(const BallisticModel& m) { return m.magnus_per_rad * m.spin_radps; }

// One RK4 step of a model's state (any model).
void StepModel(const BallisticModel& m, Eigen::Vector3d* p, Eigen::Vector3d* v, double dt) {
  const Eigen::Vector3d sv = MagnusVector(m);
  double pa[3] = {p->x(), p->y(), p->z()}, va[3] = {v->x(), v->y(), v->z()};
  const double sa[3] = {sv.x(), sv.y(), sv.z()};
  PropagateFlight(pa, va, m.drag_per_m, sa, m.gravity_mps2, dt);
  *p = {pa[0], pa[1], pa[2]};
  *v = {va[0], va[1], va[2]};
}

// Least-squares line per axis through gravity-corrected positions q = p + (0, 0, g t^2 / 2)
// (relative to t_ref): q(t) = a + b (t - t_ref). A ballistic arc without drag is a line in q.
struct GravityLine {
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double t_ref = 0.0, t_mean = 0.0, sxx = 0.0;
  int n = 0;
  double sse = 0.0;  // sum of squared 3D residuals
  Eigen::Vector3d At(double t, double g) const {
    Eigen::Vector3d q = a + b * (t - t_ref);
    q.z() -= 0.5 * g * (t - t_ref) * (t - t_ref);
    return q;
  }
  // Standard error factor (per unit noise) of the prediction at t and of the slope.
  double PredictionSd(double t) const {
    return std::sqrt(1.0 / n + (t - t_mean) * (t - t_mean) / std::max(sxx, 1e-12));
  }
  double SlopeSd() const { return 1.0 / std::sqrt(std::max(sxx, 1e-12)); }
};

GravityLine FitGravityLine(const std::vector<BallSample>& track, const std::vector<int>& idx,
                           double g, double t_ref) {
  GravityLine L;
  L.t_ref = t_ref;
  L.n = static_cast<int>(idx.size());
  if (idx.empty()) return L;
  auto q = [&](int i) {
    const double dt = track[i].time_s - t_ref;
    Eigen::Vector3d v = track[i].ball_in_world;
    v.z() += 0.5 * g * dt * dt;
    return v;
  };
  double tm = 0;
  Eigen::Vector3d qm = Eigen::Vector3d::Zero();
  for (int i : idx) {
    tm += track[i].time_s;
    qm += q(i);
  }
  tm /= L.n;
  qm /= L.n;
  double sxx = 0;
  Eigen::Vector3d sxq = Eigen::Vector3d::Zero();
  for (int i : idx) {
    const double d = track[i].time_s - tm;
    sxx += d * d;
    sxq += d * (q(i) - qm);
  }
  L.t_mean = tm;
  L.sxx = sxx;
  L.b = sxx > 1e-12 ? Eigen::Vector3d(sxq / sxx) : Eigen::Vector3d::Zero();
  L.a = qm + L.b * (t_ref - tm);
  for (int i : idx) {
    const Eigen::Vector3d r = q(i) - (L.a + L.b * (track[i].time_s - t_ref));
    L.sse += r.squaredNorm();
  }
  return L;
}

// Indices of up to `want` and at least `min_n` samples from `list` next to position `pos`
// (inclusive), going backwards (dir = -1) or forwards (+1), not beyond list positions [lo, hi),
// preferring those within window_s of the first.
std::vector<int> Window(const std::vector<int>& list, const std::vector<BallSample>& track, int pos,
                        int dir, int lo, int hi, double window_s, int min_n) {
  std::vector<int> out;
  if (pos < lo || pos >= hi) return out;
  const double t0 = track[list[pos]].time_s;
  for (int p = pos; p >= lo && p < hi; p += dir) {
    const double dt = std::abs(track[list[p]].time_s - t0);
    if (dt > window_s && static_cast<int>(out.size()) >= min_n) break;
    if (dt > 3 * window_s) break;
    out.push_back(list[p]);
  }
  if (dir < 0) std::reverse(out.begin(), out.end());
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// BallisticModel

void BallisticModel::StateAt(double time_s, Eigen::Vector3d* p_m, Eigen::Vector3d* v_mps) const {
  const double dt = time_s - t0_s;
  if (Parabola()) {
    Eigen::Vector3d p = p0_m + v0_mps * dt;
    p.z() -= 0.5 * gravity_mps2 * dt * dt;
    Eigen::Vector3d v = v0_mps;
    v.z() -= gravity_mps2 * dt;
    if (p_m) *p_m = p;
    if (v_mps) *v_mps = v;
    return;
  }
  Eigen::Vector3d p = p0_m, v = v0_mps;
  StepModel(*this, &p, &v, dt);
  if (p_m) *p_m = p;
  if (v_mps) *v_mps = v;
}

void BallisticModel::Advance(double dt_s, Eigen::Vector3d* p_m, Eigen::Vector3d* v_mps) const {
  if (Parabola()) {
    *p_m += *v_mps * dt_s;
    p_m->z() -= 0.5 * gravity_mps2 * dt_s * dt_s;
    v_mps->z() -= gravity_mps2 * dt_s;
  } else {
    StepModel(*this, p_m, v_mps, dt_s);
  }
}

std::vector<Eigen::Vector3d> BallisticModel::PositionsAt(const std::vector<double>& times_s) const {
  std::vector<Eigen::Vector3d> out(times_s.size());
  if (times_s.empty()) return out;
  if (Parabola()) {
    for (size_t i = 0; i < times_s.size(); ++i) out[i] = PositionAt(times_s[i]);
    return out;
  }
  Eigen::Vector3d p, v;
  StateAt(times_s[0], &p, &v);
  out[0] = p;
  for (size_t i = 1; i < times_s.size(); ++i) {
    Advance(times_s[i] - times_s[i - 1], &p, &v);
    out[i] = p;
  }
  return out;
}

double BallisticModel::SpinRevPerS() const { return spin_radps.norm() / (2 * M_PI); }

Eigen::Vector3d BallisticModel::PositionAt(double time_s) const {
  Eigen::Vector3d p;
  StateAt(time_s, &p, nullptr);
  return p;
}

Eigen::Vector3d BallisticModel::VelocityAt(double time_s) const {
  Eigen::Vector3d v;
  StateAt(time_s, nullptr, &v);
  return v;
}

std::optional<double> BallisticModel::CrossingTime(double z_m, double from_s, bool forward,
                                                   double max_s) const {
  // The height is unimodal in time (vz only decreases while positive and stays negative), so the
  // ascending crossing lies before the apex and the descending one after it. Walks in small
  // steps: first to the apex if from_s is on the other side of it, then away from the apex (or
  // back towards it when already below z_m).
  const double h = (forward ? 1.0 : -1.0) * (Parabola() ? 0.005 : kMaxStepS);
  Eigen::Vector3d p, v;
  StateAt(from_s, &p, &v);
  double t = from_s;
  auto step = [&](double dt) {
    if (Parabola()) {
      p += v * dt;
      p.z() -= 0.5 * gravity_mps2 * dt * dt;
      v.z() -= gravity_mps2 * dt;
    } else {
      StepModel(*this, &p, &v, dt);
    }
    t += dt;
  };
  // Beyond the apex side: ascending side has vz > 0 (forward in time: descending, vz < 0).
  auto before_apex = [&] { return forward ? v.z() > 0 : v.z() < 0; };
  bool moved = false;
  while (before_apex() && std::abs(t - from_s) < max_s) {
    step(h);
    moved = true;
  }
  const double dir = p.z() >= z_m ? 1.0 : -1.0;  // -1: walk back towards the apex
  if (dir < 0 && moved) return std::nullopt;     // the apex is below z_m
  while (std::abs(t - from_s) < max_s) {
    const double z_prev = p.z(), t_prev = t;
    step(dir * h);
    if ((p.z() - z_m) * (z_prev - z_m) <= 0 && p.z() != z_prev) {
      // Newton steps from the interpolated crossing.
      double tc = t_prev + (z_m - z_prev) / (p.z() - z_prev) * (t - t_prev);
      for (int it = 0; it < 4; ++it) {
        Eigen::Vector3d pc, vc;
        StateAt(tc, &pc, &vc);
        if (std::abs(vc.z()) < 1e-9) break;
        tc -= (pc.z() - z_m) / vc.z();
      }
      return tc;
    }
    if (dir < 0 && before_apex()) return std::nullopt;
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------

DragMode ParseDragMode(const std::string& s, const std::string& context) {
  if (s == "off") return DragMode::kOff;
  if (s == "on") return DragMode::kOn;
  if (s == "auto") return DragMode::kAuto;
  Throw("{}: drag mode must be off, on or auto (got '{}')", context, s);
}

const char* DragModeName(DragMode m) {
  switch (m) {
    case DragMode::kOff:
      return "off";
    case DragMode::kOn:
      return "on";
    default:
      return "auto";
  }
}

const char* FlightModelName(FlightModel m) {
  switch (m) {
    case FlightModel::kGravity:
      return "gravity";
    case FlightModel::kDrag:
      return "drag";
    default:
      return "spin";
  }
}

double TrajectoryOptions::MagnusPerRad() const {
  return lift_slope * air_density_kgpm3 * M_PI * std::pow(ball_radius_m, 3) / (2 * ball_mass_kg);
}

const char* FlightEventName(FlightEvent e) {
  switch (e) {
    case FlightEvent::kBounce:
      return "bounce";
    case FlightEvent::kGround:
      return "ground";
    case FlightEvent::kHit:
      return "hit";
    case FlightEvent::kTrackStart:
      return "track start";
    default:
      return "track end";
  }
}

void TrajectoryOptions::Check() const {
  // Upper limits far beyond any sport (and any planet's surface), so that products stay finite.
  CheckInRange(gravity_mps2, 1e-6, 1000.0, "gravity_mps2");
  CheckInRange(ball_radius_m, 1e-6, 1.0, "ball_radius_m");
  CheckInRange(ground_z_m, -1e4, 1e4, "ground_z_m");
  CheckInRange(noise_m, 0.0, 100.0, "noise_m");
  CheckPositive(window_s, "window_s");
  FV_REQUIRE(window_samples >= 3, "window_samples must be >= 3 (got {})", window_samples);
  CheckNonNegative(min_velocity_change_mps, "min_velocity_change_mps");
  CheckPositive(break_sigmas, "break_sigmas");
  CheckNonNegative(unmodelled_accel_mps2, "unmodelled_accel_mps2");
  CheckPositive(outlier_sigmas, "outlier_sigmas");
  CheckNonNegative(min_outlier_m, "min_outlier_m");
  CheckNonNegative(ground_tolerance_m, "ground_tolerance_m");
  CheckNonNegative(min_ground_s, "min_ground_s");
  CheckPositive(max_resting_vz_mps, "max_resting_vz_mps");
  CheckPositive(max_gap_s, "max_gap_s");
  FV_REQUIRE(min_flight_samples >= 3, "min_flight_samples must be >= 3 (got {})",
             min_flight_samples);
  CheckPositive(max_drag_per_m, "max_drag_per_m");
  FV_REQUIRE(max_iterations >= 1, "max_iterations must be >= 1 (got {})", max_iterations);
  FV_REQUIRE(spin_min_samples >= 10, "spin_min_samples must be >= 10 (got {})", spin_min_samples);
  CheckNonNegative(spin_min_span_s, "spin_min_span_s");
  CheckNonNegative(spin_min_bic_gain, "spin_min_bic_gain");
  CheckPositive(ball_mass_kg, "ball_mass_kg");
  CheckPositive(air_density_kgpm3, "air_density_kgpm3");
  CheckPositive(lift_slope, "lift_slope");
  CheckPositive(spin_prior_revps, "spin_prior_revps");
  CheckPositive(spin_along_prior_revps, "spin_along_prior_revps");
  bounce.Check();
}

double EstimateTrackNoise(const std::vector<BallSample>& track, double g) {
  // Normalised second differences of q = p + (0, 0, g t^2 / 2): zero for a drag-free arc, noise
  // with the sample's sigma otherwise; the median absolute value is robust to bounces and hits.
  std::vector<double> e;
  for (size_t i = 1; i + 1 < track.size(); ++i) {
    const double h1 = track[i].time_s - track[i - 1].time_s;
    const double h2 = track[i + 1].time_s - track[i].time_s;
    if (h1 <= 0 || h2 <= 0) continue;
    const double t0 = track[i].time_s;
    auto q = [&](size_t j) {
      Eigen::Vector3d v = track[j].ball_in_world;
      const double dt = track[j].time_s - t0;
      v.z() += 0.5 * g * dt * dt;
      return v;
    };
    const Eigen::Vector3d d = (q(i + 1) - q(i)) / h2 - (q(i) - q(i - 1)) / h1;
    const double w = std::sqrt(1 / (h2 * h2) + std::pow(1 / h1 + 1 / h2, 2) + 1 / (h1 * h1));
    for (int a = 0; a < 3; ++a) e.push_back(std::abs(d[a]) / w);
  }
  if (e.empty()) return 0.01;
  return std::max(1e-3, util::kMadToSigma * util::NearestRankPercentile(e, 0.5));
}

BallisticFit FitBallistic(const std::vector<BallSample>& samples, bool fit_drag,
                          const TrajectoryOptions& options, double noise_m) {
  return FitBallistic(samples, fit_drag ? FlightModel::kDrag : FlightModel::kGravity, options,
                      noise_m);
}

namespace {

// A fitted model's residuals over all samples given: rmse, inliers by a robust threshold
// (outlier_sigmas times the larger of the noise and the residuals' MAD sigma), the capped sum of
// squares and the Bayesian information criterion (Schwarz 1978) that compares the models.
void ScoreFit(const std::vector<BallSample>& samples, double t_ref,
              const TrajectoryOptions& options, double noise_m, BallisticFit* fit_out) {
  BallisticFit& fit = *fit_out;
  const int n = static_cast<int>(samples.size());
  std::vector<double> r(n);
  double ss = 0;
  if (fit.model.Parabola()) {
    for (int i = 0; i < n; ++i) {
      r[i] = (fit.model.PositionAt(samples[i].time_s) - samples[i].ball_in_world).norm();
    }
  } else {
    // Walk once through the samples (sorted by time) in both directions from t_ref.
    Eigen::Vector3d p, v;
    for (int dir : {1, -1}) {
      fit.model.StateAt(t_ref, &p, &v);
      double t = t_ref;
      for (int i = n / 2; i >= 0 && i < n; i += dir) {
        StepModel(fit.model, &p, &v, samples[i].time_s - t);
        t = samples[i].time_s;
        r[i] = (p - samples[i].ball_in_world).norm();
      }
    }
  }
  for (double x : r) ss += x * x;
  fit.rmse_m = std::sqrt(ss / n);
  const double robust_sigma =
      util::kMadToSigma * util::NearestRankPercentile(r, 0.5) / std::sqrt(3.0);
  const double thr =
      std::max(options.outlier_sigmas * std::max(noise_m, robust_sigma), options.min_outlier_m);
  for (int i = 0; i < n; ++i) {
    fit.inlier[i] = r[i] <= thr;
    fit.inliers += fit.inlier[i];
  }
  const double cap = std::max(options.outlier_sigmas * std::max(noise_m, 1e-4) * std::sqrt(3.0),
                              options.min_outlier_m);
  for (double x : r) fit.capped_sse_m2 += std::min(x * x, cap * cap);
  const double nobs = 3.0 * n;
  fit.bic =
      nobs * std::log(std::max(fit.capped_sse_m2, 1e-18) / nobs) + fit.parameters * std::log(nobs);
}

// d cost / d k of the samples' robust cost (FlightResiduals) at these parameters.
double CostSlopeInDrag(FlightPath* path, const std::vector<double>& dt_s,
                       const std::vector<Eigen::Vector3d>& x_m, double g, double huber,
                       const double* p0, const double* v0, const double* k, const double* sm) {
  const FlightResiduals cost(path, dt_s, x_m, g, huber);
  std::vector<double> r(cost.num_residuals()), dr_dk(cost.num_residuals());
  const double* params[4] = {p0, v0, k, sm};
  double* jacobians[4] = {nullptr, nullptr, dr_dk.data(), nullptr};
  cost.Evaluate(params, r.data(), jacobians);
  double slope = 0.0;
  for (size_t i = 0; i < r.size(); ++i) slope += r[i] * dr_dk[i];
  return slope;
}

// The parameters a fit starts from: those of `start` at t_ref when given (warm, true), else the
// gravity line through all samples (false); k and the Magnus vector as each model needs them.
bool StartState(const std::vector<BallSample>& samples, FlightModel kind,
                const TrajectoryOptions& options, double t_ref, const BallisticModel* start,
                double p0[3], double v0[3], double k[1], double sm[3]) {
  constexpr double kDragStartPerM = 0.01;  // a cold drag stage's first k
  k[0] = kind != FlightModel::kGravity ? kDragStartPerM : 0.0;
  sm[0] = sm[1] = sm[2] = 0.0;
  if (start == nullptr) {
    std::vector<int> all(samples.size());
    std::iota(all.begin(), all.end(), 0);
    const GravityLine line = FitGravityLine(samples, all, options.gravity_mps2, t_ref);
    for (int i = 0; i < 3; ++i) p0[i] = line.a[i], v0[i] = line.b[i];
    return false;
  }
  Eigen::Vector3d p, v;
  start->StateAt(t_ref, &p, &v);
  for (int i = 0; i < 3; ++i) p0[i] = p[i], v0[i] = v[i];
  if (kind != FlightModel::kGravity) {
    k[0] = std::clamp(start->drag_per_m, 0.0, options.max_drag_per_m);
  }
  // A drag fit from a parabola starts where a cold one's drag stage does.
  if (kind == FlightModel::kDrag && start->Parabola()) k[0] = kDragStartPerM;
  if (kind == FlightModel::kSpin) {
    const Eigen::Vector3d s0 = MagnusVector(*start);
    for (int i = 0; i < 3; ++i) sm[i] = s0[i];
  }
  return true;
}

}  // namespace

BallisticFit FitBallistic(const std::vector<BallSample>& samples, FlightModel kind,
                          const TrajectoryOptions& options, double noise_m,
                          const BallisticModel* start) {
  BallisticFit fit;
  const int n = static_cast<int>(samples.size());
  fit.inlier.assign(n, false);
  fit.parameters = kind == FlightModel::kGravity ? 6 : kind == FlightModel::kDrag ? 7 : 10;
  if (n < 3) return fit;
  const double g = options.gravity_mps2;
  const double t_ref = samples[n / 2].time_s;
  const double c_m = options.MagnusPerRad();
  double p0[3], v0[3], k[1], sm[3];
  const bool warm = StartState(samples, kind, options, t_ref, start, p0, v0, k, sm);
  const double huber = 3.0 * std::max(noise_m, 1e-3);
  // The drag and spin models' residuals read one path integrated through all samples.
  std::vector<double> dt_s(n);
  for (int i = 0; i < n; ++i) dt_s[i] = samples[i].time_s - t_ref;
  FlightPath path(dt_s, g);
  std::vector<Eigen::Vector3d> x_m(n);
  for (int i = 0; i < n; ++i) x_m[i] = samples[i].ball_in_world;
  // hold_k: k stays where it is (0: the drag model's lower bound).
  auto solve = [&](FlightModel m, bool hold_k = false) {
    ceres::Problem problem;
    // Every sample under its own Huber loss (one block for all: FlightResiduals).
    problem.AddResidualBlock(
        new FlightResiduals(m == FlightModel::kGravity ? nullptr : &path, dt_s, x_m, g, huber),
        nullptr, p0, v0, k, sm);
    if (m != FlightModel::kGravity && !hold_k) {
      problem.SetParameterLowerBound(k, 0, 0.0);
      problem.SetParameterUpperBound(k, 0, options.max_drag_per_m);
    } else {
      problem.SetParameterBlockConstant(k);
    }
    if (m == FlightModel::kSpin) {
      // The prior costs as much as one sample off by the noise when each component is at
      // spin_prior_revps.
      const double unit = std::max(noise_m, 1e-3) / (c_m * 2 * M_PI);
      Eigen::Vector3d dir(v0[0], v0[1], v0[2]);
      dir = dir.norm() > 1e-6 ? Eigen::Vector3d(dir.normalized()) : Eigen::Vector3d::UnitX();
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<SpinPrior, 3, 3>(new SpinPrior(
              dir, unit / options.spin_prior_revps, unit / options.spin_along_prior_revps)),
          nullptr, sm);
    } else {
      problem.SetParameterBlockConstant(sm);
    }
    ceres::Solver::Options so;
    so.max_num_iterations = options.max_iterations;
    so.linear_solver_type = ceres::DENSE_QR;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    fit.iterations += static_cast<int>(summary.iterations.size());
    return summary.IsSolutionUsable();
  };
  // Cold starts go up the hierarchy (gravity, drag, spin), each from the one before. Where the
  // cost does not fall as k leaves its lower bound 0 at the optimum for k = 0 (d cost / d k >= 0,
  // Karush-Kuhn-Tucker), that optimum is the bounded problem's: k = 0 is kept, the drag stage from
  // a parabola's optimum needs no solve and the spin stage from k = 0 is solved with k held (the
  // bounded solve creeps along the bound: most of the iterations of drag-free flights).
  auto no_drag_is_optimal = [&] {
    const double k_was = k[0];
    k[0] = 0.0;
    if (CostSlopeInDrag(&path, dt_s, x_m, g, huber, p0, v0, k, sm) >= 0.0) return true;
    k[0] = k_was;
    return false;
  };
  bool ok = true;
  if (!warm || kind == FlightModel::kGravity) ok = solve(FlightModel::kGravity);
  if (ok && kind != FlightModel::kGravity && !(warm && kind == FlightModel::kSpin)) {
    // From a parabola: its optimum for these samples first (at once from their gravity fit).
    const bool parabola = !warm || start->Parabola();
    if (warm && parabola) ok = solve(FlightModel::kGravity);
    if (ok && !(parabola && no_drag_is_optimal())) ok = solve(FlightModel::kDrag);
  }
  if (ok && kind == FlightModel::kSpin) {
    const double p0_was[3] = {p0[0], p0[1], p0[2]}, v0_was[3] = {v0[0], v0[1], v0[2]},
                 sm_was[3] = {sm[0], sm[1], sm[2]};
    const bool held = k[0] == 0.0 && solve(FlightModel::kSpin, true) && no_drag_is_optimal();
    if (!held) {
      for (int i = 0; i < 3; ++i) p0[i] = p0_was[i], v0[i] = v0_was[i], sm[i] = sm_was[i];
      ok = solve(FlightModel::kSpin);
    }
  }
  fit.model.t0_s = t_ref;
  fit.model.p0_m = Eigen::Vector3d(p0[0], p0[1], p0[2]);
  fit.model.v0_mps = Eigen::Vector3d(v0[0], v0[1], v0[2]);
  fit.model.gravity_mps2 = g;
  fit.model.drag_per_m = kind != FlightModel::kGravity ? k[0] : 0.0;
  if (kind == FlightModel::kSpin && c_m > 0) {
    fit.model.magnus_per_rad = c_m;
    fit.model.spin_radps = Eigen::Vector3d(sm[0], sm[1], sm[2]) / c_m;
  }
  ScoreFit(samples, t_ref, options, noise_m, &fit);
  fit.ok = ok && std::isfinite(fit.rmse_m);
  fit.path_sweeps = path.sweeps();
  fit.path_steps = path.steps();
  return fit;
}

Eigen::Vector3d ConstantAccelerationFit::PositionAt(double time_s) const {
  const double dt = time_s - t0_s;
  return p0_m + v0_mps * dt + 0.5 * accel_mps2 * dt * dt;
}

std::optional<double> ConstantAccelerationFit::DescendingCrossing(double z_m, double from_s) const {
  // z(t) = z_m: 0.5 a dt^2 + v dt + (p - z_m) = 0, the later root after from_s.
  const double a = 0.5 * accel_mps2.z(), b = v0_mps.z(), c = p0_m.z() - z_m;
  std::vector<double> roots;
  if (std::abs(a) < 1e-12) {
    if (std::abs(b) > 1e-12) roots.push_back(-c / b);
  } else {
    const double disc = b * b - 4 * a * c;
    if (disc < 0) return std::nullopt;
    roots.push_back((-b - std::sqrt(disc)) / (2 * a));
    roots.push_back((-b + std::sqrt(disc)) / (2 * a));
  }
  std::optional<double> best;
  for (double dt : roots) {
    const double t = t0_s + dt;
    const double vz = b + 2 * a * dt;
    if (t >= from_s && vz < 0 && (!best || t < *best)) best = t;
  }
  return best;
}

ConstantAccelerationFit FitConstantAcceleration(const std::vector<BallSample>& samples) {
  ConstantAccelerationFit f;
  const int n = static_cast<int>(samples.size());
  if (n < 4) return f;
  f.t0_s = samples[n / 2].time_s;
  Eigen::MatrixXd A(n, 3);
  Eigen::MatrixXd B(n, 3);
  for (int i = 0; i < n; ++i) {
    const double dt = samples[i].time_s - f.t0_s;
    A.row(i) << 1, dt, 0.5 * dt * dt;
    B.row(i) = samples[i].ball_in_world.transpose();
  }
  const Eigen::MatrixXd X = A.colPivHouseholderQr().solve(B);  // 3 x 3: rows p0, v0, a
  if (!X.allFinite()) return f;
  f.p0_m = X.row(0).transpose();
  f.v0_mps = X.row(1).transpose();
  f.accel_mps2 = X.row(2).transpose();
  double ss = 0;
  for (int i = 0; i < n; ++i) {
    ss += (f.PositionAt(samples[i].time_s) - samples[i].ball_in_world).squaredNorm();
  }
  f.rmse_m = std::sqrt(ss / n);
  f.ok = true;
  return f;
}

PlaneQuadraticFit FitPlaneQuadratic(const std::vector<BallSample>& samples,
                                    const TrajectoryOptions& options) {
  PlaneQuadraticFit f;
  const int n = static_cast<int>(samples.size());
  if (n < 3) {
    f.failure = "fewer than 3 points";
    return f;
  }
  const Eigen::Vector2d xy0 = samples.front().ball_in_world.head<2>();
  Eigen::Vector2d d = samples.back().ball_in_world.head<2>() - xy0;
  if (d.norm() < 0.05) {
    f.failure = "vertical flight (no horizontal direction)";
    return f;
  }
  d.normalize();
  const Eigen::Vector2d nrm(-d.y(), d.x());
  auto s_of = [&](const BallSample& b) { return (b.ball_in_world.head<2>() - xy0).dot(d); };
  // The seed: the quadratic through the last three points.
  Eigen::Matrix3d A3;
  Eigen::Vector3d z3;
  for (int j = 0; j < 3; ++j) {
    const double s = s_of(samples[n - 3 + j]);
    A3.row(j) << s * s, s, 1;
    z3[j] = samples[n - 3 + j].ball_in_world.z();
  }
  Eigen::Vector3d c = A3.colPivHouseholderQr().solve(z3);
  // Refined with all points (linear least squares).
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd z(n), tt(n);
  Eigen::MatrixXd B(n, 2);
  for (int i = 0; i < n; ++i) {
    const double s = s_of(samples[i]);
    A.row(i) << s * s, s, 1;
    z[i] = samples[i].ball_in_world.z();
    B.row(i) << s, 1;
    tt[i] = samples[i].time_s;
  }
  const Eigen::Vector3d c_ls = A.colPivHouseholderQr().solve(z);
  if (c_ls.allFinite()) c = c_ls;
  const Eigen::Vector2d ts = B.colPivHouseholderQr().solve(tt);  // t = ts0 s + ts1
  // Lateral offset of the plane: mean of the perpendicular coordinate.
  double off = 0;
  for (const auto& b : samples) off += (b.ball_in_world.head<2>() - xy0).dot(nrm);
  off /= n;
  double ss = 0;
  for (int i = 0; i < n; ++i) {
    const double s = s_of(samples[i]);
    const double perp = (samples[i].ball_in_world.head<2>() - xy0).dot(nrm) - off;
    const double dz = z[i] - (c[0] * s * s + c[1] * s + c[2]);
    ss += perp * perp + dz * dz;
  }
  f.rmse_m = std::sqrt(ss / n);
  if (c[0] >= 0) {
    f.failure = "curvature does not open downwards";
    return f;
  }
  const double zr = options.ground_z_m + options.ball_radius_m;
  const double disc = c[1] * c[1] - 4 * c[0] * (c[2] - zr);
  if (disc < 0) {
    f.failure = "arc never reaches the ground";
    return f;
  }
  const double s1 = (-c[1] + std::sqrt(disc)) / (2 * c[0]);
  const double s2 = (-c[1] - std::sqrt(disc)) / (2 * c[0]);
  const double sa = -c[1] / (2 * c[0]);
  auto point = [&](double s, double zz) {
    const Eigen::Vector2d p = xy0 + s * d + off * nrm;
    return Eigen::Vector3d(p.x(), p.y(), zz);
  };
  f.origin_m = point(std::min(s1, s2), zr);
  f.landing_m = point(std::max(s1, s2), zr);
  f.apex_m = point(sa, c[2] - c[1] * c[1] / (4 * c[0]));
  f.t_origin_s = ts[0] * std::min(s1, s2) + ts[1];
  f.t_landing_s = ts[0] * std::max(s1, s2) + ts[1];
  f.gravity_mps2 = std::abs(ts[0]) > 1e-9 ? -2 * c[0] / (ts[0] * ts[0]) : 0.0;
  f.ok = true;
  return f;
}

void BounceModel::Check() const {
  CheckInRange(restitution, 0.0, 1.5, "restitution");
  CheckNonNegative(friction, "friction");
  CheckPositive(inertia_factor, "inertia_factor");
}

void BounceModel::Apply(double r, Eigen::Vector3d* v, Eigen::Vector3d* w) const {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const double vn = v->z();
  if (vn >= 0) return;
  // Contact point velocity (tangential): u = v_t + w x (-r z).
  const Eigen::Vector3d vt(v->x(), v->y(), 0.0);
  const Eigen::Vector3d u = vt + w->cross(-r * z);
  // A tangential impulse J (per unit mass) changes u by J (1 + 1 / inertia_factor).
  const double gain = 1.0 + 1.0 / inertia_factor;
  const double normal = (1.0 + restitution) * -vn;  // normal impulse per unit mass
  Eigen::Vector3d J = Eigen::Vector3d::Zero();
  const double un = u.norm();
  if (un > 1e-9) J = -u / un * std::min(friction * normal, un / gain);
  *v = vt + J;
  v->z() = -restitution * vn;
  // dw = (-r z) x J / (inertia_factor r^2)
  *w += (-r * z).cross(J) / (inertia_factor * r * r);
}

BounceFit FitBounce(const Eigen::Vector3d& vb, const Eigen::Vector3d& wb, const Eigen::Vector3d& va,
                    double r, double inertia_factor) {
  BounceFit f;
  f.spin_before_radps = wb;
  if (vb.z() >= -0.1 || va.z() <= 0) return f;
  f.restitution = -va.z() / vb.z();
  // Friction: the tangential impulse seen, over the normal impulse (sliding); when the contact
  // point ended rolling, this is a lower bound and the model's result is the same.
  const Eigen::Vector3d J(va.x() - vb.x(), va.y() - vb.y(), 0.0);
  const double normal = va.z() - vb.z();
  f.friction = J.norm() / normal;
  f.spin_after_radps = wb + (-r * Eigen::Vector3d::UnitZ()).cross(J) / (inertia_factor * r * r);
  f.ok = std::isfinite(f.restitution) && std::isfinite(f.friction);
  return f;
}

std::string TrajectoryResult::Summary() const {
  int outliers = static_cast<int>(std::count(outlier.begin(), outlier.end(), true));
  int ground = static_cast<int>(std::count(on_ground.begin(), on_ground.end(), true));
  int drag = 0, spin = 0;
  for (const auto& f : flights) drag += f.drag_used && !f.spin_used, spin += f.spin_used;
  return fmt::format(
      "{} flights ({} with drag, {} with spin), {} bounces/hits, {} outliers, {} samples on the "
      "ground, {} short hops, noise {:.1f} mm",
      flights.size(), drag, spin, breaks.size(), outliers, ground, short_hops, noise_m * 1e3);
}

// ---------------------------------------------------------------------------------------------
// Segmentation

namespace {

struct Segmenter {
  const std::vector<BallSample>& track;
  const TrajectoryOptions& o;
  double sigma;

  // Whether a window's samples rest on the ground: all within the ground band and within the
  // noise (or min_outlier_m) of each other.
  bool Resting(const std::vector<int>& w) const {
    const double top_m = GroundBandTopM(o, sigma);
    const double spread_m = 2 * std::max(o.min_outlier_m, 3 * sigma);
    return !w.empty() && std::all_of(w.begin(), w.end(), [&](int k) {
      return track[k].ball_in_world.z() <= top_m &&
             (track[k].ball_in_world - track[w.front()].ball_in_world).norm() <= spread_m;
    });
  }

  // Flags samples that both neighbouring local fits miss (two passes; each fit without its own
  // worst sample when it misses that one).
  std::vector<bool> FindOutliers() const {
    const int n = static_cast<int>(track.size());
    std::vector<bool> out(n, false);
    const double g = o.gravity_mps2;
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<int> good;
      for (int i = 0; i < n; ++i) {
        if (!out[i]) good.push_back(i);
      }
      std::vector<char> next(n, 0);  // written from several threads: not vector<bool>
      std::vector<SideFit> side(n);
      const int m = static_cast<int>(good.size());
      // Each sample on its own (blocks of samples on all threads).
      constexpr int kBlock = 4096;
      util::ParallelFor((n + kBlock - 1) / kBlock, [&](size_t b) {
        for (int i = static_cast<int>(b) * kBlock;
             i < std::min(n, static_cast<int>(b + 1) * kBlock); ++i) {
          // Neighbours among the currently good samples, excluding i itself: the windows walk
          // `good` away from i (positions below lo_pos on the left, from hi_pos on the right).
          const int lo_pos =
              static_cast<int>(std::lower_bound(good.begin(), good.end(), i) - good.begin());
          const int hi_pos =
              static_cast<int>(std::upper_bound(good.begin(), good.end(), i) - good.begin());
          const auto left = Window(good, track, lo_pos - 1, -1, 0, m, o.window_s, o.window_samples);
          const auto right = Window(good, track, hi_pos, +1, 0, m, o.window_s, o.window_samples);
          int fits = 0, misses = 0;
          // Distance from a fit in units of the outlier threshold (> 1: missed).
          auto miss_ratio = [&](const GravityLine& L, int k) {
            const double err = (L.At(track[k].time_s, g) - track[k].ball_in_world).norm();
            const double sd = L.PredictionSd(track[k].time_s);
            const double thr = std::max(o.min_outlier_m, o.outlier_sigmas * sigma * std::sqrt(3.0) *
                                                             std::sqrt(1 + sd * sd));
            return err / thr;
          };
          auto misses_line = [&](const GravityLine& L, int k) { return miss_ratio(L, k) > 1.0; };
          // A window's fit without its worst sample when the fit misses that one: a glitch
          // inside the window would tilt it and make it miss the good samples next to it (three
          // 0.5 m glitches in a 0.26 s hop had all ten of its samples flagged).
          auto RobustLine = [&](const std::vector<int>& w, double t_ref, const auto& misses) {
            GravityLine L = FitGravityLine(track, w, g, t_ref);
            if (static_cast<int>(w.size()) <= o.window_samples) return L;
            size_t worst = 0;
            double worst_err = -1.0;
            for (size_t q = 0; q < w.size(); ++q) {
              const double err = (L.At(track[w[q]].time_s, g) - track[w[q]].ball_in_world).norm();
              if (err > worst_err) worst_err = err, worst = q;
            }
            if (!misses(L, w[worst])) return L;
            std::vector<int> rest = w;
            rest.erase(rest.begin() + static_cast<long>(worst));
            return FitGravityLine(track, rest, g, t_ref);
          };
          std::optional<GravityLine> missed;  // the fit of the side that missed
          bool missed_left = false;
          double fit_ratio = 0.0;  // the fitting side's miss ratio
          for (const auto* w : {&left, &right}) {
            if (static_cast<int>(w->size()) < o.window_samples) continue;
            const double span_ok = std::abs(track[(*w)[w->size() / 2]].time_s - track[i].time_s);
            if (span_ok > 3 * o.window_s) continue;
            const GravityLine L = RobustLine(*w, track[i].time_s, misses_line);
            ++fits;
            const double ratio = miss_ratio(L, i);
            if (ratio > 1.0) {
              ++misses;
              missed = L;
              missed_left = w == &left;
            } else {
              fit_ratio = ratio;
            }
          }
          if (fits == 2) {
            next[i] = misses == 2;
            if (misses == 1) side[i] = {missed_left ? 2 : 1, fit_ratio};
          } else if (fits == 1 && misses == 1) {
            // One side only (near a track end or a break): a jump there is either a glitch or the
            // start of a new arc. An outlier when the next sample on the other side returns to
            // the arc (an isolated jump). Without such a sample nothing says which, but for the
            // track's first sample before a ball at rest: no ball comes to rest from elsewhere
            // within one sample interval (a last sample away from a resting ball may be a kick).
            const int other = missed_left ? (hi_pos < m ? good[hi_pos] : -1)
                                          : (lo_pos > 0 ? good[lo_pos - 1] : -1);
            next[i] = other >= 0 ? !misses_line(*missed, other) : !missed_left && Resting(right);
          }
        }
      });
      if (pass > 0) FlagCrossedSides(out, side, &next);
      out.assign(next.begin(), next.end());
    }
    return out;
  }

  // The one side whose local fit a sample lies on, where the other side's fit misses it (at a
  // break between arcs): 1 the earlier samples, 2 the later; 0 both or neither.
  struct SideFit {
    int side = 0;
    double ratio = 0.0;  // distance from that fit in outlier thresholds
  };

  // Arcs follow each other in time: a sample on only the earlier arc cannot come after one on
  // only the later arc. Of two such neighbours that both fits missed in the pass before (a
  // glitch beside a break tilts the fits; none kept between them), one is a glitch that happens
  // to lie near the other arc's extrapolation: the one farther from its fit stays an outlier.
  static void FlagCrossedSides(const std::vector<bool>& was_outlier,
                               const std::vector<SideFit>& side, std::vector<char>* next) {
    int later_only = -1;  // the last kept sample on only the later arc
    for (int i = 0; i < static_cast<int>(side.size()); ++i) {
      if ((*next)[i]) continue;
      if (side[i].side == 1 && later_only >= 0 && was_outlier[i] && was_outlier[later_only]) {
        (*next)[side[i].ratio >= side[later_only].ratio ? i : later_only] = 1;
      }
      later_only = side[i].side == 2 ? i : -1;
    }
  }

  // Samples in ground phases: within the tolerance of the resting height for min_ground_s.
  std::vector<bool> FindGround(const std::vector<bool>& outlier) const {
    const int n = static_cast<int>(track.size());
    std::vector<bool> ground(n, false);
    const double top_m = GroundBandTopM(o, sigma);
    int i = 0;
    while (i < n) {
      if (outlier[i] || track[i].ball_in_world.z() > top_m) {
        ++i;
        continue;
      }
      int j = i, last = i;
      while (j < n && (outlier[j] || track[j].ball_in_world.z() <= top_m)) {
        if (!outlier[j]) last = j;
        if (j > i && track[j].time_s - track[j - 1].time_s > o.max_gap_s) break;
        ++j;
      }
      // A run at a track end may have lasted longer than seen: a few samples suffice there, when
      // they are not moving up or down (a ball arriving at or leaving the ground is not).
      int count = 0;
      for (int k = i; k <= last; ++k) count += !outlier[k];
      const double dt_run = track[last].time_s - track[i].time_s;
      const bool level =
          dt_run > 0 &&
          std::abs(track[last].ball_in_world.z() - track[i].ball_in_world.z()) / dt_run <
              o.max_resting_vz_mps;
      const bool at_end = (i == 0 || j >= n) && level;
      if (track[last].time_s - track[i].time_s >= o.min_ground_s ||
          (at_end && count >= o.window_samples)) {
        for (int k = i; k <= last; ++k) ground[k] = !outlier[k];
      }
      i = std::max(j, i + 1);
    }
    return ground;
  }

  struct Candidate {
    double ratio = 0.0;
    int pos = -1;
    double dv = 0.0;
  };

  // The velocity jump at the gap after list position k, windows limited to [lo, hi).
  Candidate Score(const std::vector<int>& list, int k, int lo, int hi) const {
    Candidate c;
    const auto left = Window(list, track, k, -1, lo, hi, o.window_s, o.window_samples);
    const auto right = Window(list, track, k + 1, +1, lo, hi, o.window_s, o.window_samples);
    if (static_cast<int>(left.size()) < o.window_samples ||
        static_cast<int>(right.size()) < o.window_samples) {
      return c;
    }
    const double g = o.gravity_mps2;
    const double tc = 0.5 * (track[list[k]].time_s + track[list[k + 1]].time_s);
    const GravityLine L = FitGravityLine(track, left, g, tc);
    const GravityLine R = FitGravityLine(track, right, g, tc);
    const double dv = (R.b - L.b).norm();
    // Standard error of the jump (3D), plus a slack for unmodelled drag/spin (5 m/s^2 over
    // the windows' half spans).
    const double sd = sigma * std::sqrt(3.0) * std::hypot(L.SlopeSd(), R.SlopeSd());
    const double span = track[right.back()].time_s - track[left.front()].time_s;
    const double thr = std::max(o.min_velocity_change_mps,
                                o.break_sigmas * sd + o.unmodelled_accel_mps2 * 0.5 * span);
    c.ratio = dv / thr;
    c.pos = k;
    c.dv = dv;
    return c;
  }

  // Sum of squared residuals of splitting list[a..b] after position k.
  double SplitCost(const std::vector<int>& list, int a, int b, int k) const {
    std::vector<int> l(list.begin() + a, list.begin() + k + 1);
    std::vector<int> r(list.begin() + k + 1, list.begin() + b + 1);
    if (l.size() < 2 || r.size() < 2) return std::numeric_limits<double>::infinity();
    const double tc = track[list[k]].time_s;
    return FitGravityLine(track, l, o.gravity_mps2, tc).sse +
           FitGravityLine(track, r, o.gravity_mps2, tc).sse;
  }

  // Greedy: the largest jump above threshold becomes a break, until none is left. Each gap's
  // score is kept and only the gaps whose windows reach a new break are scored again, so a long
  // block with many breaks costs O(n log n) instead of O(n x breaks^2) (the same breaks).
  std::vector<int> FindBreaks(const std::vector<int>& list, int lo, int hi) const {
    std::set<int> breaks;  // positions k: break between list[k] and list[k+1]
    // Windows of the gap after k stay within the breaks around it.
    auto bounds = [&](int k, int* a, int* b) {
      if (breaks.count(k)) return false;  // already a break
      *a = lo;
      *b = hi;
      const auto it = breaks.lower_bound(k);  // the first break after k
      if (it != breaks.end()) *b = std::min(*b, *it + 1);
      if (it != breaks.begin()) *a = std::max(*a, *std::prev(it) + 1);
      return *a < *b;
    };
    // Per gap k in [lo, hi), at k - lo (the block's size, not the list's: a long track has
    // thousands of blocks).
    const int m = std::max(hi - lo, 0);
    std::vector<double> queued(m, -1.0);     // ratio in `queue`, -1: none
    std::set<std::pair<double, int>> queue;  // (-ratio, k): largest, then first
    std::vector<Candidate> score(m);
    auto rescore = [&](int k) {
      if (queued[k - lo] >= 0) queue.erase({-queued[k - lo], k});
      queued[k - lo] = -1.0;
      int a = 0, b = 0;
      if (!bounds(k, &a, &b)) return;
      score[k - lo] = Score(list, k, a, b);
      if (score[k - lo].ratio > 1.0) {
        queued[k - lo] = score[k - lo].ratio;
        queue.insert({-queued[k - lo], k});
      }
    };
    for (int k = lo; k + 1 < hi; ++k) rescore(k);
    const double reach_s = 4 * o.window_s;  // beyond any window (3 window_s), with a margin
    while (!queue.empty()) {
      const Candidate best = score[queue.begin()->second - lo];
      // Localise: the split of the neighbourhood with the least residual.
      int a = std::max(lo, best.pos - 2 * o.window_samples);
      int b = std::min(hi - 1, best.pos + 1 + 2 * o.window_samples);
      const auto it = breaks.lower_bound(best.pos);
      if (it != breaks.end()) b = std::min(b, *it);
      if (it != breaks.begin()) a = std::max(a, *std::prev(it) + 1);
      int k_best = best.pos;
      double c_best = SplitCost(list, a, b, best.pos);
      for (int k = std::max(a + 1, best.pos - 2); k <= std::min(b - 2, best.pos + 2); ++k) {
        if (breaks.count(k)) continue;
        const double c = SplitCost(list, a, b, k);
        if (c < c_best) {
          c_best = c;
          k_best = k;
        }
      }
      breaks.insert(k_best);
      // The gaps whose windows could include the samples on either side of the new break.
      const double t_lo = track[list[k_best]].time_s - reach_s;
      const double t_hi = track[list[k_best + 1]].time_s + reach_s;
      int k0 = k_best, k1 = k_best;
      while (k0 > lo && track[list[k0]].time_s >= t_lo) --k0;
      while (k1 + 2 < hi && track[list[k1 + 1]].time_s <= t_hi) ++k1;
      for (int k = std::max(lo, k0 - 2); k <= std::min(hi - 2, k1 + 2); ++k) rescore(k);
    }
    return std::vector<int>(breaks.begin(), breaks.end());
  }
};

double ApexOf(const BallisticModel& m, double t0, double t1, double* t_apex) {
  double best = -std::numeric_limits<double>::infinity();
  const int steps = std::clamp(static_cast<int>((t1 - t0) / 0.002), 2, 2000);
  Eigen::Vector3d p, v;
  double t = t0;
  m.StateAt(t0, &p, &v);
  for (int s = 0; s <= steps; ++s) {
    const double ts = t0 + (t1 - t0) * s / steps;
    if (m.Parabola()) {
      p = m.PositionAt(ts);
    } else {
      StepModel(m, &p, &v, ts - t);
      t = ts;
    }
    if (p.z() > best) {
      best = p.z();
      *t_apex = ts;
    }
  }
  return best;
}

// The time where two arcs are closest, searched around [t_a, t_b].
double MeetingTime(const BallisticModel& a, const BallisticModel& b, double t_a, double t_b) {
  const double lo = t_a - 0.05, hi = t_b + 0.05;
  double best_t = 0.5 * (t_a + t_b), best = std::numeric_limits<double>::infinity();
  const int steps = std::clamp(static_cast<int>((hi - lo) / 0.0005), 4, 4000);
  std::vector<double> times(steps + 1);
  for (int s = 0; s <= steps; ++s) times[s] = lo + (hi - lo) * s / steps;
  const auto pa = a.PositionsAt(times), pb = b.PositionsAt(times);
  for (int s = 0; s <= steps; ++s) {
    const double d = (pa[s] - pb[s]).norm();
    if (d < best) {
      best = d;
      best_t = times[s];
    }
  }
  return best_t;
}

// A run of airborne samples between two events: positions a..b (inclusive) in the list of
// airborne inliers.
struct Piece {
  int a, b;
  FlightEvent start, end;
};

// The airborne inliers (`air`, track indices) cut into blocks at ground phases and gaps longer
// than max_gap_s, each block split at the breaks the segmenter finds (kHit until the fitted arcs
// tell a bounce from a hit).
std::vector<Piece> CutIntoPieces(const std::vector<BallSample>& track,
                                 const std::vector<bool>& on_ground, const std::vector<int>& air,
                                 const Segmenter& seg, const TrajectoryOptions& options) {
  const int n = static_cast<int>(track.size());
  auto ground_in = [&](int i0, int i1) {  // any ground sample in [i0, i1)
    for (int k = std::max(i0, 0); k < std::min(i1, n); ++k) {
      if (on_ground[k]) return true;
    }
    return false;
  };
  std::vector<Piece> pieces;
  int block_start = 0;
  const int m = static_cast<int>(air.size());
  for (int p = 0; p < m; ++p) {
    const bool last = p + 1 == m;
    const int next = last ? n : air[p + 1];
    const bool cut = last || ground_in(air[p] + 1, next) ||
                     track[next].time_s - track[air[p]].time_s > options.max_gap_s;
    if (!cut) continue;
    const int prev = block_start == 0 ? 0 : air[block_start - 1] + 1;
    const FlightEvent start_ev =
        ground_in(prev, air[block_start]) ? FlightEvent::kGround : FlightEvent::kTrackStart;
    const FlightEvent end_ev =
        ground_in(air[p] + 1, next) ? FlightEvent::kGround : FlightEvent::kTrackEnd;
    const std::vector<int> brk = seg.FindBreaks(air, block_start, p + 1);
    int a = block_start;
    FlightEvent ev = start_ev;
    for (int br : brk) {
      pieces.push_back({a, br, ev, FlightEvent::kHit});
      a = br + 1;
      ev = FlightEvent::kHit;  // bounce or hit: decided from the fitted arcs
    }
    pieces.push_back({a, p, ev, end_ev});
    block_start = p + 1;
  }
  return pieces;
}

// How many samples at one end of `s` (the start or the end) lie off the arc, in a run from that
// end: off the fit of all samples and off the gravity fit of the 8 samples next to the 3 at the
// end (ScoreFit's rule over those 11). The whole flight's parabola misses the ends of a flight
// with drag, and a hop's samples pull it; the local fit is not asked when there are fewer than 11
// samples or it misses one of its own 8 (a glitch there tilts it). More than 3 is a longer run of
// misses: model error such as spin.
int MissedAtEnd(const std::vector<BallSample>& s, bool at_start, const BallisticFit& all,
                const TrajectoryOptions& options, double noise_m) {
  constexpr int kEnd = 3, kCore = 8;
  const int ns = static_cast<int>(s.size());
  std::vector<bool> on_arc(ns);  // from the end inwards
  for (int i = 0; i < ns; ++i) on_arc[i] = all.inlier[at_start ? i : ns - 1 - i];
  if (ns >= kEnd + kCore) {
    // The kEnd + kCore samples at this end, in time order; the core is the inner kCore.
    const auto first = at_start ? s.begin() : s.end() - kEnd - kCore;
    const std::vector<BallSample> local(first, first + kEnd + kCore);
    const int core_begin = at_start ? kEnd : 0;
    const std::vector<BallSample> core(local.begin() + core_begin,
                                       local.begin() + core_begin + kCore);
    BallisticFit fit = FitBallistic(core, false, options, noise_m);
    fit.inlier.assign(local.size(), false);
    fit.inliers = 0;
    fit.capped_sse_m2 = 0.0;
    ScoreFit(local, fit.model.t0_s, options, noise_m, &fit);
    // A judge whose own samples lie on its arc (a glitch among them would tilt it).
    const bool clean =
        fit.ok && std::all_of(fit.inlier.begin() + core_begin,
                              fit.inlier.begin() + core_begin + kCore, [](bool b) { return b; });
    if (clean) {
      for (int i = 0; i <= kEnd; ++i) {
        on_arc[i] = on_arc[i] || fit.inlier[at_start ? i : kEnd + kCore - 1 - i];
      }
    }
  }
  int run = 0;
  while (run < kEnd + 1 && run < ns && !on_arc[run]) ++run;
  return run;
}

// Leading and trailing samples the arc misses belong to a neighbouring hop too short to be split
// off by the local fits: drops them (at most 3 a side; a longer run of misses is model error such
// as spin, kept) and fits again. True when it dropped any.
bool TrimMissedEnds(const TrajectoryOptions& options, double noise_m, std::vector<BallSample>* s,
                    Flight* f) {
  const int ns = static_cast<int>(s->size());
  int lead = MissedAtEnd(*s, true, f->no_drag, options, noise_m);
  int trail = lead >= ns ? 0 : MissedAtEnd(*s, false, f->no_drag, options, noise_m);
  if (lead > 3) lead = 0;
  if (trail > 3) trail = 0;
  if ((lead == 0 && trail == 0) || ns - lead - trail < options.min_flight_samples) return false;
  *s = std::vector<BallSample>(s->begin() + lead, s->end() - trail);
  f->samples = std::vector<int>(f->samples.begin() + lead, f->samples.end() - trail);
  f->no_drag = FitBallistic(*s, false, options, noise_m);
  return true;
}

// Samples of the neighbouring ground phases that lie on the arc (the approach to a contact within
// the ground tolerance) join it and leave the ground phase; the first one that does not bounds
// the contact time (*lo before the arc, *hi after it).
void JoinGroundApproach(const std::vector<BallSample>& track, const std::vector<bool>& outlier,
                        const TrajectoryOptions& options, double noise_m,
                        std::vector<bool>* on_ground, std::vector<BallSample>* s, Flight* f,
                        double* lo, double* hi) {
  const int n = static_cast<int>(track.size());
  *lo = -std::numeric_limits<double>::infinity();
  *hi = std::numeric_limits<double>::infinity();
  const double thr = OffArcM(options, noise_m);
  // On the arc, where the arc is not yet (or no longer) below the ground by more than 3 sigma:
  // a sample at rest after the arc came down belongs to the next phase, however near it lies.
  const double lowest_m = options.ground_z_m + options.ball_radius_m - 3 * noise_m;
  auto consistent = [&](int k) {
    const Eigen::Vector3d p = f->no_drag.model.PositionAt(track[k].time_s);
    return p.z() >= lowest_m && (p - track[k].ball_in_world).norm() <= thr;
  };
  bool added = false;
  for (int k = f->samples.front() - 1; k >= 0; --k) {
    if (outlier[k]) continue;
    if (!(*on_ground)[k] || !consistent(k)) {
      *lo = track[k].time_s;
      break;
    }
    f->samples.insert(f->samples.begin(), k);
    (*on_ground)[k] = false;
    added = true;
  }
  for (int k = f->samples.back() + 1; k < n; ++k) {
    if (outlier[k]) continue;
    if (!(*on_ground)[k] || !consistent(k)) {
      *hi = track[k].time_s;
      break;
    }
    f->samples.push_back(k);
    (*on_ground)[k] = false;
    added = true;
  }
  if (added) {
    s->clear();
    for (int k : f->samples) s->push_back(track[k]);
    f->no_drag = FitBallistic(*s, false, options, noise_m);
  }
}

// The drag and spin fits the options ask for, and which model the flight uses: drag when it
// lowers the RMSE by 10 % (or is forced), spin when it lowers the BIC by spin_min_bic_gain.
// `piece_samples` is the piece's size before trimming (the drag fit's sample rule). False when
// no model fits (a short hop).
bool ChooseModel(const std::vector<BallSample>& s, int piece_samples,
                 const TrajectoryOptions& options, double noise_m, Flight* f) {
  f->t_first_seen_s = s.front().time_s;
  f->t_last_seen_s = s.back().time_s;
  const double span = f->t_last_seen_s - f->t_first_seen_s;
  const bool try_drag = options.drag == DragMode::kOn ||
                        (options.drag == DragMode::kAuto && piece_samples >= 8 && span >= 0.15);
  // From the gravity fit of these samples: the cold fit's first stage (the same result).
  if (try_drag) {
    f->with_drag = FitBallistic(s, FlightModel::kDrag, options, noise_m,
                                f->no_drag.ok ? &f->no_drag.model : nullptr);
  }
  f->drag_used = f->with_drag.ok &&
                 (options.drag == DragMode::kOn || f->with_drag.rmse_m < 0.9 * f->no_drag.rmse_m);
  const bool try_spin =
      options.spin == SpinMode::kOn ||
      (options.spin == SpinMode::kAuto && static_cast<int>(s.size()) >= options.spin_min_samples &&
       span >= options.spin_min_span_s);
  if (try_spin) {
    const BallisticFit& base = f->drag_used ? f->with_drag : f->no_drag;
    if (base.ok) f->with_spin = FitBallistic(s, FlightModel::kSpin, options, noise_m, &base.model);
    if (!f->with_spin.ok) f->with_spin = FitBallistic(s, FlightModel::kSpin, options, noise_m);
    f->spin_used = f->with_spin.ok && (options.spin == SpinMode::kOn || !base.ok ||
                                       f->with_spin.bic < base.bic - options.spin_min_bic_gain);
  }
  if (!f->no_drag.ok && !f->drag_used && !f->spin_used) return false;
  f->rmse_m = f->spin_used   ? f->with_spin.rmse_m
              : f->drag_used ? f->with_drag.rmse_m
                             : f->no_drag.rmse_m;
  return true;
}

// A piece on its way to a flight (FitPiece's stages).
struct FittedPiece {
  Flight flight;
  std::vector<BallSample> s;                               // the samples fitted
  int count = 0;                                           // the piece's samples before trimming
  double lo_s = -std::numeric_limits<double>::infinity();  // the contact times before and after
  double hi_s = std::numeric_limits<double>::infinity();   // lie within these
  bool trimmed = false;                                    // missed ends were dropped
};

// The first stage of fitting a piece (pieces in any order): its gravity fit without the ends it
// misses; nullopt for a hop too short to fit.
std::optional<FittedPiece> StartPiece(const std::vector<BallSample>& track,
                                      const std::vector<int>& air, const Piece& pc,
                                      const TrajectoryOptions& options, double noise_m) {
  FittedPiece fp;
  fp.count = pc.b - pc.a + 1;
  if (fp.count < options.min_flight_samples) return std::nullopt;
  Flight& f = fp.flight;
  for (int p = pc.a; p <= pc.b; ++p) {
    fp.s.push_back(track[air[p]]);
    f.samples.push_back(air[p]);
  }
  f.start_event = pc.start;
  f.end_event = pc.end;
  f.no_drag = FitBallistic(fp.s, false, options, noise_m);
  fp.trimmed = TrimMissedEnds(options, noise_m, &fp.s, &f);
  return fp;
}

// The last stage (any order, after the ground approaches are joined in track order): the drag and
// spin fits, the model chosen and the reference fits. False when no model fits (a short hop).
bool FinishPiece(const TrajectoryOptions& options, double noise_m, FittedPiece* fp) {
  Flight& f = fp->flight;
  const bool ok = ChooseModel(fp->s, fp->count, options, noise_m, &f);
  if (ok) {
    f.free_accel = FitConstantAcceleration(fp->s);
    f.seed = FitPlaneQuadratic(fp->s, options);
  }
  fp->s = {};
  return ok;
}

// Every piece fitted as a flight (the costly drag and spin fits on all threads; the same result
// as one piece after the other); nullopt for a hop too short to fit (counted in *short_hops, as
// are trimmed ends). Joined ground samples leave *on_ground.
std::vector<std::optional<FittedPiece>> FitPieces(const std::vector<BallSample>& track,
                                                  const std::vector<int>& air,
                                                  const std::vector<Piece>& pieces,
                                                  const std::vector<bool>& outlier,
                                                  const TrajectoryOptions& options, double noise_m,
                                                  std::vector<bool>* on_ground, int* short_hops) {
  std::vector<std::optional<FittedPiece>> fitted(pieces.size());
  util::ParallelFor(pieces.size(), [&](size_t i) {
    fitted[i] = StartPiece(track, air, pieces[i], options, noise_m);
  });
  // A piece takes the ground samples next to it that lie on its arc: in track order.
  for (auto& fp : fitted) {
    if (!fp) {
      ++*short_hops;
      continue;
    }
    *short_hops += fp->trimmed;
    JoinGroundApproach(track, outlier, options, noise_m, on_ground, &fp->s, &fp->flight, &fp->lo_s,
                       &fp->hi_s);
  }
  std::mutex progress_mutex;
  size_t done = 0;
  std::vector<char> ok(pieces.size(), 0);
  util::ParallelFor(pieces.size(), [&](size_t i) {
    if (fitted[i]) ok[i] = FinishPiece(options, noise_m, &*fitted[i]);
    if (options.progress) {
      const std::lock_guard<std::mutex> lock(progress_mutex);
      options.progress(++done, pieces.size());
    }
  });
  for (size_t i = 0; i < pieces.size(); ++i) {
    if (fitted[i] && !ok[i]) {
      ++*short_hops;
      fitted[i].reset();
    }
  }
  return fitted;
}

// A piece at the track's start or end whose samples and fitted arc all stay within the ground band
// (FindGround's) is the ball at rest or rolling before a kick or after it settles, too few
// samples for a ground phase: its arc would be a flight of a few centimetres.
bool RestsAtTrackEnd(const std::vector<BallSample>& track, const Piece& pc, const Flight& f,
                     const TrajectoryOptions& options, double noise_m) {
  if (pc.start != FlightEvent::kTrackStart && pc.end != FlightEvent::kTrackEnd) return false;
  const double band_m = GroundBandTopM(options, noise_m);
  for (int k : f.samples) {
    if (track[k].ball_in_world.z() > band_m) return false;
  }
  double t_apex = 0.0;
  return ApexOf(f.model(), f.t_first_seen_s, f.t_last_seen_s, &t_apex) <= band_m;
}

}  // namespace

namespace detail {

namespace {

// The samples of a hop hidden between a bounce's two arcs: the arcs do not meet, the arc after it
// rises from the ground at least a sample interval after the arc before it came down, and samples
// between their seen spans after that landing lie off both (left as outliers or trimmed). Empty
// when there is no such hop. Real bounces can have arcs apart by centimetres and crossings frames
// apart (table tennis at 180 Hz: 6 cm, 25 ms) but no sample between them.
std::vector<BallSample> UnseenHopSamples(const std::vector<BallSample>& track, const Flight& A,
                                         const Flight& B, double gap_m, double off_m,
                                         const TrajectoryOptions& options, double sample_interval_s,
                                         double* landed_s) {
  std::vector<BallSample> hop;
  if (!(gap_m > off_m)) return hop;
  const double zr = options.ground_z_m + options.ball_radius_m;
  const auto landed = A.model().CrossingTime(zr, A.t_last_seen_s, true, 10.0);
  const auto rose = B.model().CrossingTime(zr, B.t_first_seen_s, false, 10.0);
  if (!landed || !rose || *rose - *landed < sample_interval_s) return hop;
  *landed_s = *landed;
  const auto first = std::upper_bound(track.begin(), track.end(), *landed,
                                      [](double t, const BallSample& s) { return t < s.time_s; });
  for (auto it = first; it != track.end() && it->time_s < B.t_first_seen_s; ++it) {
    const double off_a = (A.model().PositionAt(it->time_s) - it->ball_in_world).norm();
    const double off_b = (B.model().PositionAt(it->time_s) - it->ball_in_world).norm();
    if (off_a > off_m && off_b > off_m) hop.push_back(*it);
  }
  return hop;
}

// The hop from A's landing point through its samples (gravity only, its start fixed), and the kick
// where it meets B's arc between its last sample and B's first: A ends in a bounce there, B starts
// with a hit. False (nothing changed) when the hop does not rise or does not meet B's arc within
// 2 off_m.
bool ResolveUnseenHop(const std::vector<BallSample>& hop, double landed_s, double off_m,
                      const TrajectoryOptions& options, Flight* A, Flight* B,
                      std::vector<TrackBreak>* breaks) {
  BallisticModel m;
  m.t0_s = landed_s;
  m.p0_m = A->model().PositionAt(landed_s);
  m.gravity_mps2 = options.gravity_mps2;
  // Least squares for the launch velocity: sum over samples of dt (x - p0 + g dt^2 / 2) / dt^2.
  Eigen::Vector3d num = Eigen::Vector3d::Zero();
  double den = 0.0;
  for (const BallSample& s : hop) {
    const double dt = s.time_s - landed_s;
    Eigen::Vector3d r = s.ball_in_world - m.p0_m;
    r.z() += 0.5 * m.gravity_mps2 * dt * dt;
    num += dt * r;
    den += dt * dt;
  }
  if (!(den > 0)) return false;
  m.v0_mps = num / den;
  if (m.v0_mps.z() <= 0) return false;
  constexpr double kStepS = 0.0005;
  double t_hit = hop.back().time_s, closest_m = std::numeric_limits<double>::infinity();
  for (double t = hop.back().time_s; t <= B->t_first_seen_s + 1e-9; t += kStepS) {
    const double d = (m.PositionAt(t) - B->model().PositionAt(t)).norm();
    if (d < closest_m) {
      closest_m = d;
      t_hit = t;
    }
  }
  if (closest_m > 2 * off_m) return false;
  const Eigen::Vector3d va = A->model().VelocityAt(landed_s);
  TrackBreak bounce;
  bounce.time_s = landed_s;
  bounce.ball_in_world = m.p0_m;
  bounce.velocity_change_mps = (m.v0_mps - va).norm();
  bounce.kind = FlightEvent::kBounce;
  bounce.bounce = FitBounce(va, A->model().spin_radps, m.v0_mps, options.ball_radius_m);
  TrackBreak hit;
  hit.time_s = t_hit;
  hit.ball_in_world = 0.5 * (m.PositionAt(t_hit) + B->model().PositionAt(t_hit));
  hit.velocity_change_mps = (B->model().VelocityAt(t_hit) - m.VelocityAt(t_hit)).norm();
  hit.kind = FlightEvent::kHit;
  A->end_event = FlightEvent::kBounce;
  B->start_event = FlightEvent::kHit;
  B->t_start_s = t_hit;
  breaks->push_back(bounce);
  breaks->push_back(hit);
  return true;
}

}  // namespace

void ResolveContacts(const std::vector<BallSample>& track, const std::vector<int>& piece_of_flight,
                     const TrajectoryOptions& options, double noise_m, std::vector<Flight>* flights,
                     std::vector<TrackBreak>* breaks) {
  std::vector<double> intervals_s;
  intervals_s.reserve(track.size());
  for (size_t i = 1; i < track.size(); ++i) {
    intervals_s.push_back(track[i].time_s - track[i - 1].time_s);
  }
  const double sample_interval_s = util::NearestRankPercentile(intervals_s, 0.5);
  const double off_m = OffArcM(options, noise_m);
  // A contact up to 5 cm above the ground band is low enough for a bounce.
  const double bounce_top_m = GroundBandTopM(options, noise_m) + 0.05;
  for (size_t i = 0; i + 1 < flights->size(); ++i) {
    Flight& A = (*flights)[i];
    Flight& B = (*flights)[i + 1];
    if (piece_of_flight[i + 1] != piece_of_flight[i] + 1) continue;
    if (A.end_event != FlightEvent::kHit || B.start_event != FlightEvent::kHit) {
      if (A.end_event == FlightEvent::kHit) A.end_event = FlightEvent::kGround;
      if (B.start_event == FlightEvent::kHit) B.start_event = FlightEvent::kGround;
      continue;
    }
    const double tm = MeetingTime(A.model(), B.model(), A.t_last_seen_s, B.t_first_seen_s);
    const Eigen::Vector3d pa = A.model().PositionAt(tm);
    const Eigen::Vector3d pb = B.model().PositionAt(tm);
    const Eigen::Vector3d va = A.model().VelocityAt(tm);
    const Eigen::Vector3d vb = B.model().VelocityAt(tm);
    TrackBreak br;
    br.time_s = tm;
    br.ball_in_world = 0.5 * (pa + pb);
    br.velocity_change_mps = (vb - va).norm();
    br.kind = (br.ball_in_world.z() < bounce_top_m && va.z() < 0 && vb.z() > 0)
                  ? FlightEvent::kBounce
                  : FlightEvent::kHit;
    double landed_s = 0.0;
    const std::vector<BallSample> hop =
        br.kind == FlightEvent::kBounce ? UnseenHopSamples(track, A, B, (pa - pb).norm(), off_m,
                                                           options, sample_interval_s, &landed_s)
                                        : std::vector<BallSample>();
    if (!hop.empty()) {
      // The bounce, the hop and the kick; or two ground contacts, each arc's own (as next to a
      // hop too short to fit), when the hop does not join them.
      if (!ResolveUnseenHop(hop, landed_s, off_m, options, &A, &B, breaks)) {
        A.end_event = B.start_event = FlightEvent::kGround;
      }
      continue;
    }
    if (br.kind == FlightEvent::kBounce) {
      br.bounce = FitBounce(va, A.model().spin_radps, vb, options.ball_radius_m);
    }
    A.end_event = br.kind;
    B.start_event = br.kind;
    if (br.kind == FlightEvent::kHit) {
      A.t_end_s = tm;
      B.t_start_s = tm;
    }
    breaks->push_back(br);
  }
  for (size_t i = 0; i < flights->size(); ++i) {
    Flight& f = (*flights)[i];
    const bool prev_fitted = i > 0 && piece_of_flight[i - 1] + 1 == piece_of_flight[i];
    const bool next_fitted =
        i + 1 < flights->size() && piece_of_flight[i + 1] == piece_of_flight[i] + 1;
    if (f.start_event == FlightEvent::kHit && !prev_fitted) f.start_event = FlightEvent::kGround;
    if (f.end_event == FlightEvent::kHit && !next_fitted) f.end_event = FlightEvent::kGround;
  }
}

namespace {

bool InTheAir(const BallisticModel& m, double t_s, const TrajectoryOptions& options) {
  return m.PositionAt(t_s).z() > GroundBandTopM(options, 0.0);
}

}  // namespace

void PlaceEndpoints(const TrajectoryOptions& options, double lo_s, double hi_s, Flight* f) {
  const double zr = options.ground_z_m + options.ball_radius_m;
  const BallisticModel& mdl = f->model();
  if (f->start_event == FlightEvent::kHit) {
    f->origin_m = mdl.PositionAt(f->t_start_s);
  } else {
    const auto t0 = mdl.CrossingTime(zr, f->t_first_seen_s, false, 10.0);
    f->t_start_s = t0 ? *t0 : f->t_first_seen_s;
    // Kicked while rolling or hopping low: the arc starts after the last sample off it. When the
    // arc is then well above the ground it began in the air (a touch, or a hop too short to fit).
    if (f->start_event == FlightEvent::kGround && lo_s > f->t_start_s) {
      f->t_start_s = lo_s;
      if (InTheAir(mdl, lo_s, options)) f->start_event = FlightEvent::kHit;
    }
    f->origin_m = mdl.PositionAt(f->t_start_s);
  }
  const auto t1 = mdl.CrossingTime(zr, f->t_last_seen_s, true, 10.0);
  f->t_landing_s = t1 ? *t1 : f->t_last_seen_s;
  // The first sample off the arc after it bounds a ground contact; an arc still well above the
  // ground there ended in the air, and where it would have landed is extrapolated.
  if (f->end_event == FlightEvent::kGround && hi_s < f->t_landing_s) {
    if (InTheAir(mdl, hi_s, options)) {
      f->end_event = FlightEvent::kHit;
      f->t_end_s = hi_s;
    } else {
      f->t_landing_s = hi_s;
    }
  }
  f->landing_m = mdl.PositionAt(f->t_landing_s);
  // At a ground contact the ball's centre is a radius above the ground (CONTRACT.md): an arc
  // started at a rolling ball's last sample, or ended at the first one after it, is there within
  // the ground band, not on it (the kick render's origin 0.8 mm up).
  if (f->start_event == FlightEvent::kGround) f->origin_m.z() = zr;
  if (f->end_event == FlightEvent::kGround) f->landing_m.z() = zr;
  if (f->end_event != FlightEvent::kHit) f->t_end_s = f->t_landing_s;
  f->origin_extrapolated = f->start_event == FlightEvent::kTrackStart;
  f->landing_extrapolated =
      f->end_event == FlightEvent::kHit || f->end_event == FlightEvent::kTrackEnd;
  f->v0_mps = mdl.VelocityAt(f->t_start_s);
  f->speed_mps = f->v0_mps.norm();
  f->apex_m = mdl.PositionAt(f->t_start_s);
  ApexOf(mdl, f->t_start_s, f->t_end_s, &f->t_apex_s);
  f->apex_m = mdl.PositionAt(f->t_apex_s);
}

void MergeBounces(const std::vector<BallSample>& track, const TrajectoryOptions& options,
                  std::vector<Flight>* flights) {
  for (size_t i = 0; i + 1 < flights->size(); ++i) {
    Flight& A = (*flights)[i];
    Flight& B = (*flights)[i + 1];
    if (A.end_event != FlightEvent::kBounce || B.start_event != FlightEvent::kBounce) continue;
    const double tc = 0.5 * (A.t_landing_s + B.t_start_s);
    const double la =
        FitGravityLine(track, A.samples, options.gravity_mps2, tc).PredictionSd(A.t_landing_s);
    const double lb =
        FitGravityLine(track, B.samples, options.gravity_mps2, tc).PredictionSd(B.t_start_s);
    const double wa = 1 / (la * la), wb = 1 / (lb * lb);
    const Eigen::Vector3d c = (wa * A.landing_m + wb * B.origin_m) / (wa + wb);
    const double t = (wa * A.t_landing_s + wb * B.t_start_s) / (wa + wb);
    A.landing_m = B.origin_m = c;
    A.t_landing_s = A.t_end_s = B.t_start_s = t;
    B.v0_mps = B.model().VelocityAt(t);
    B.speed_mps = B.v0_mps.norm();
  }
}

void AttachOutliers(const std::vector<BallSample>& track, const std::vector<bool>& outlier,
                    Flight* f) {
  // The samples within the seen span (times increase along the track).
  const auto lo = std::lower_bound(track.begin(), track.end(), f->t_first_seen_s,
                                   [](const BallSample& s, double t) { return s.time_s < t; });
  const auto hi = std::upper_bound(track.begin(), track.end(), f->t_last_seen_s,
                                   [](double t, const BallSample& s) { return t < s.time_s; });
  for (auto it = lo; it < hi; ++it) {
    const size_t k = it - track.begin();
    if (outlier[k]) f->samples.push_back(static_cast<int>(k));
  }
  std::sort(f->samples.begin(), f->samples.end());
}

}  // namespace detail

using detail::AttachOutliers;
using detail::MergeBounces;
using detail::PlaceEndpoints;
using detail::ResolveContacts;

TrajectoryResult AnalyzeTrajectory(const std::vector<BallSample>& track,
                                   const TrajectoryOptions& options) {
  options.Check();
  for (size_t i = 1; i < track.size(); ++i) {
    FV_REQUIRE(track[i].time_s > track[i - 1].time_s,
               "ball track: times must increase (sample {} at {} s follows {} s)", i,
               track[i].time_s, track[i - 1].time_s);
  }
  TrajectoryResult res;
  const int n = static_cast<int>(track.size());
  res.outlier.assign(n, false);
  res.on_ground.assign(n, false);
  res.noise_m =
      options.noise_m > 0 ? options.noise_m : EstimateTrackNoise(track, options.gravity_mps2);
  if (n < 3) return res;
  const Segmenter seg{track, options, res.noise_m};
  res.outlier = seg.FindOutliers();
  res.on_ground = seg.FindGround(res.outlier);

  std::vector<int> air;  // airborne inliers
  for (int i = 0; i < n; ++i) {
    if (!res.outlier[i] && !res.on_ground[i]) air.push_back(i);
  }
  const std::vector<Piece> pieces = CutIntoPieces(track, res.on_ground, air, seg, options);
  std::vector<Flight> flights;
  std::vector<int> piece_of_flight;
  std::vector<std::pair<double, double>> limits;  // contact times lie within these
  auto fitted = FitPieces(track, air, pieces, res.outlier, options, res.noise_m, &res.on_ground,
                          &res.short_hops);
  for (size_t pi = 0; pi < pieces.size(); ++pi) {
    if (fitted[pi] &&
        RestsAtTrackEnd(track, pieces[pi], fitted[pi]->flight, options, res.noise_m)) {
      for (int k : fitted[pi]->flight.samples) res.on_ground[k] = true;
      fitted[pi].reset();
    }
    if (!fitted[pi]) continue;
    flights.push_back(std::move(fitted[pi]->flight));
    piece_of_flight.push_back(static_cast<int>(pi));
    limits.emplace_back(fitted[pi]->lo_s, fitted[pi]->hi_s);
  }
  ResolveContacts(track, piece_of_flight, options, res.noise_m, &flights, &res.breaks);
  for (size_t i = 0; i < flights.size(); ++i) {
    flights[i].index = static_cast<int>(i);
    PlaceEndpoints(options, limits[i].first, limits[i].second, &flights[i]);
  }
  MergeBounces(track, options, &flights);
  for (Flight& f : flights) AttachOutliers(track, res.outlier, &f);
  res.flights = std::move(flights);
  return res;
}

}  // namespace fv::recon
