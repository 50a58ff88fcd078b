#include "fieldvision/recon/trajectory_predict.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "fieldvision/util/error.h"

namespace fv::recon {
namespace {

using Vec10 = Eigen::Matrix<double, 10, 1>;

// Parameters: p0 (3), v0 (3), k, the Magnus vector c_M w (3).
BallisticModel WithParams(const BallisticModel& m, const Vec10& th, double c_m) {
  BallisticModel r = m;
  r.p0_m = th.head<3>();
  r.v0_mps = th.segment<3>(3);
  r.drag_per_m = th[6];
  if (c_m > 0) {
    r.magnus_per_rad = c_m;
    r.spin_radps = th.tail<3>() / c_m;
  }
  return r;
}

}  // namespace

LandingPrediction PredictLanding(const std::vector<BallSample>& samples, bool fit_drag,
                                 const TrajectoryOptions& options, double noise_m) {
  return PredictLanding(samples, fit_drag ? FlightModel::kDrag : FlightModel::kGravity, options,
                        noise_m);
}

LandingPrediction PredictLanding(const std::vector<BallSample>& samples, FlightModel kind,
                                 const TrajectoryOptions& options, double noise_m) {
  LandingPrediction pr;
  pr.samples_used = static_cast<int>(samples.size());
  if (samples.size() < 4) return pr;
  pr.t_cut_s = samples.back().time_s;
  pr.model = kind;
  const BallisticFit fit = FitBallistic(samples, kind, options, noise_m);
  if (!fit.ok) return pr;
  pr.fit_rmse_m = fit.rmse_m;
  const double zr = options.ground_z_m + options.ball_radius_m;
  const BallisticModel& m = fit.model;
  auto landing = [&](const BallisticModel& mm, Eigen::Vector3d* out) {
    const auto t = mm.CrossingTime(zr, samples.back().time_s, true, 10.0);
    if (!t) return false;
    const Eigen::Vector3d p = mm.PositionAt(*t);
    *out = Eigen::Vector3d(p.x(), p.y(), *t);
    return true;
  };
  Eigen::Vector3d L0;
  if (!landing(m, &L0)) return pr;
  Vec10 th;
  const double c_m = kind == FlightModel::kSpin ? options.MagnusPerRad() : 0.0;
  th << m.p0_m, m.v0_mps, m.drag_per_m, c_m * m.spin_radps;
  const int np = kind == FlightModel::kGravity ? 6 : kind == FlightModel::kDrag ? 7 : 10;
  // Jacobian of the residuals (numerical), inliers only.
  std::vector<int> used;
  for (size_t i = 0; i < samples.size(); ++i) {
    if (fit.inlier[i]) used.push_back(static_cast<int>(i));
  }
  if (static_cast<int>(used.size()) < 4) return pr;
  std::vector<double> used_times;
  used_times.reserve(used.size());
  for (int i : used) used_times.push_back(samples[i].time_s);
  Eigen::MatrixXd J(3 * used.size(), np);
  Eigen::Matrix<double, 3, Eigen::Dynamic> JL(3, np);
  for (int p = 0; p < np; ++p) {
    const double h = p >= 6 ? 1e-5 : 1e-6;
    Vec10 a = th, b = th;
    a[p] += h;
    b[p] -= h;
    const BallisticModel ma = WithParams(m, a, c_m), mb = WithParams(m, b, c_m);
    const auto pa = ma.PositionsAt(used_times), pb = mb.PositionsAt(used_times);
    for (size_t k = 0; k < used.size(); ++k) J.block<3, 1>(3 * k, p) = (pa[k] - pb[k]) / (2 * h);
    Eigen::Vector3d la, lb;
    if (!landing(ma, &la) || !landing(mb, &lb)) return pr;
    JL.col(p) = (la - lb) / (2 * h);
  }
  const double sigma = std::max(noise_m, fit.rmse_m / std::sqrt(3.0));
  const Eigen::MatrixXd JtJ = J.transpose() * J;
  const Eigen::MatrixXd cov = sigma * sigma * JtJ.ldlt().solve(Eigen::MatrixXd::Identity(np, np));
  const Eigen::Matrix3d cl = JL * cov * JL.transpose();
  pr.landing_m = Eigen::Vector3d(L0.x(), L0.y(), zr);
  pr.t_landing_s = L0.z();
  pr.cov_xy_m2 = cl.topLeftCorner<2, 2>();
  pr.sigma_t_s = std::sqrt(std::max(0.0, cl(2, 2)));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(pr.cov_xy_m2);
  const double chi2_95 = 5.991;  // 2 degrees of freedom
  pr.semi_major_m = std::sqrt(chi2_95 * std::max(0.0, es.eigenvalues()[1]));
  pr.semi_minor_m = std::sqrt(chi2_95 * std::max(0.0, es.eigenvalues()[0]));
  pr.angle_rad = std::atan2(es.eigenvectors()(1, 1), es.eigenvectors()(0, 1));
  pr.ok = pr.landing_m.allFinite() && std::isfinite(pr.semi_major_m);
  return pr;
}

FlightModel PredictionModel(const Flight& flight, const std::vector<BallSample>& /*samples*/,
                            const TrajectoryOptions& /*options*/, double /*noise_m*/) {
  return flight.model_kind();
}

LandingPrediction PredictFlightLanding(const std::vector<BallSample>& track,
                                       const TrajectoryResult& result, const Flight& flight,
                                       double fraction, const TrajectoryOptions& options) {
  CheckInRange(fraction, 0.05, 1.0, "fraction");
  // From the first sample seen (an extrapolated origin may lie far before it).
  const double t0 = std::max(flight.t_start_s, flight.t_first_seen_s);
  const double t_cut = t0 + fraction * (flight.t_end_s - t0);
  std::vector<BallSample> s;
  for (size_t k = 0; k < flight.samples.size(); ++k) {
    const int i = flight.samples[k];
    if (track[i].time_s > t_cut) break;
    if (!result.outlier[i]) s.push_back(track[i]);
  }
  return PredictLanding(s, PredictionModel(flight, s, options, result.noise_m), options,
                        result.noise_m);
}

void SmootherOptions::Check() const {
  CheckPositive(accel_noise_mps2, "accel_noise_mps2");
  CheckNonNegative(noise_m, "noise_m");
}

namespace {

// Outliers in a run without inliers (between two flights' seen spans, as at a bounce): the
// position of the flight whose span [start, end] holds their time, else the line between the
// smoothed positions around the run (the nearest one at a track end).
void FillUnseen(const std::vector<BallSample>& track, const TrajectoryResult& result,
                const std::vector<bool>& unseen, std::vector<BallSample>* out) {
  const int n = static_cast<int>(track.size());
  for (int i = 0; i < n; ++i) {
    if (!unseen[i]) continue;
    const double t = track[i].time_s;
    const Flight* holder = nullptr;
    for (const Flight& f : result.flights) {
      if (t >= f.t_start_s && t <= f.t_end_s) holder = &f;
    }
    if (holder != nullptr) {
      (*out)[i].ball_in_world = holder->model().PositionAt(t);
      continue;
    }
    int a = i - 1, b = i + 1;
    while (a >= 0 && unseen[a]) --a;
    while (b < n && unseen[b]) ++b;
    if (a < 0 && b >= n) continue;  // nothing seen at all: the track's own positions
    if (a < 0 || b >= n) {
      (*out)[i].ball_in_world = (*out)[a < 0 ? b : a].ball_in_world;
      continue;
    }
    const double w = (t - track[a].time_s) / (track[b].time_s - track[a].time_s);
    (*out)[i].ball_in_world = (1 - w) * (*out)[a].ball_in_world + w * (*out)[b].ball_in_world;
  }
}

}  // namespace

std::vector<BallSample> SmoothTrack(const std::vector<BallSample>& track,
                                    const TrajectoryResult& result,
                                    const TrajectoryOptions& options, const SmootherOptions& so) {
  so.Check();
  const int n = static_cast<int>(track.size());
  std::vector<BallSample> out = track;
  if (n == 0) return out;
  FV_REQUIRE(result.outlier.size() == track.size(),
             "SmoothTrack: the analysis result does not belong to this track ({} vs {} samples)",
             result.outlier.size(), track.size());
  // Segments: each flight's seen span (with gravity); the rest in runs without gravity.
  std::vector<int> seg(n, -1);
  std::vector<bool> gravity;
  auto before_time = [](const BallSample& s, double t) { return s.time_s < t; };
  auto after_time = [](double t, const BallSample& s) { return t < s.time_s; };
  for (const auto& f : result.flights) {
    const int id = static_cast<int>(gravity.size());
    gravity.push_back(true);
    // The samples within the seen span (times increase along the track).
    const auto lo = std::lower_bound(track.begin(), track.end(), f.t_first_seen_s, before_time);
    const auto hi = std::upper_bound(track.begin(), track.end(), f.t_last_seen_s, after_time);
    for (auto it = lo; it < hi; ++it) seg[it - track.begin()] = id;
  }
  for (int i = 0; i < n; ++i) {
    if (seg[i] >= 0) continue;
    const int id = static_cast<int>(gravity.size());
    gravity.push_back(false);
    while (i < n && seg[i] < 0) seg[i++] = id;
    --i;
  }
  const double sigma = so.noise_m > 0 ? so.noise_m : std::max(result.noise_m, 1e-3);
  const double q = so.accel_noise_mps2 * so.accel_noise_mps2;
  const double g = options.gravity_mps2;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  std::vector<bool> unseen(n, false);  // in a segment without inliers: filled in afterwards
  int i = 0;
  while (i < n) {
    int j = i;
    while (j < n && seg[j] == seg[i]) ++j;
    const bool grav = gravity[seg[i]];
    const int m = j - i;
    int first_inlier = i;
    while (first_inlier < j && result.outlier[first_inlier]) ++first_inlier;
    if (first_inlier == j) {
      for (int k = i; k < j; ++k) unseen[k] = true;
      i = j;
      continue;
    }
    std::vector<Vec6> xf(m), xp(m);
    std::vector<Mat6> Pf(m), Pp(m), F(m);
    Vec6 x = Vec6::Zero();
    x.head<3>() = track[first_inlier].ball_in_world;
    Mat6 P = Mat6::Zero();
    P.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * 1.0;
    P.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * 400.0;
    for (int k = 0; k < m; ++k) {
      const int idx = i + k;
      Mat6 Fk = Mat6::Identity();
      if (k > 0) {
        const double dt = track[idx].time_s - track[idx - 1].time_s;
        Fk.topRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * dt;
        Mat6 Q = Mat6::Zero();
        Q.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * q * dt * dt * dt / 3;
        Q.topRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * q * dt * dt / 2;
        Q.bottomLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * q * dt * dt / 2;
        Q.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * q * dt;
        x = Fk * x;
        if (grav) {
          x[2] -= 0.5 * g * dt * dt;
          x[5] -= g * dt;
        }
        P = Fk * P * Fk.transpose() + Q;
      }
      F[k] = Fk;
      xp[k] = x;
      Pp[k] = P;
      if (!result.outlier[idx]) {
        const Eigen::Vector3d y = track[idx].ball_in_world - x.head<3>();
        const Eigen::Matrix3d S =
            P.topLeftCorner<3, 3>() + Eigen::Matrix3d::Identity() * sigma * sigma;
        const Eigen::Matrix<double, 6, 3> K = P.leftCols<3>() * S.inverse();
        x += K * y;
        P = (Mat6::Identity() - K * Eigen::Matrix<double, 3, 6>::Identity()) * P;
      }
      xf[k] = x;
      Pf[k] = P;
    }
    // Rauch-Tung-Striebel backward pass.
    Vec6 xs = xf[m - 1];
    out[j - 1].ball_in_world = xs.head<3>();
    for (int k = m - 2; k >= 0; --k) {
      const Mat6 C = Pf[k] * F[k + 1].transpose() * Pp[k + 1].inverse();
      xs = xf[k] + C * (xs - xp[k + 1]);
      out[i + k].ball_in_world = xs.head<3>();
    }
    i = j;
  }
  FillUnseen(track, result, unseen, &out);
  return out;
}

}  // namespace fv::recon
