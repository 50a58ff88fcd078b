#include "fieldvision/recon/trajectory_eval.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "fieldvision/recon/trajectory_predict.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace fv::recon {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double RmseOr(const BallisticFit& f) { return f.ok ? f.rmse_m : kNaN; }

double MedianFinite(const std::vector<BounceTrackScore>& v, double BounceTrackScore::*m) {
  std::vector<double> x;
  for (const auto& s : v) {
    if (s.scored && std::isfinite(s.*m)) x.push_back(s.*m);
  }
  return x.empty() ? kNaN : util::Median(x);
}

}  // namespace

void BounceEvalOptions::Check() const {
  CheckInRange(prediction_fraction, 0.1, 0.9, "prediction_fraction");
  CheckPositive(reference_window_s, "reference_window_s");
}

BounceTrackScore ScoreBounceTrack(const std::string& path, const std::vector<BallSample>& track,
                                  const TrajectoryOptions& options, const BounceEvalOptions& eval) {
  eval.Check();
  BounceTrackScore s;
  s.path = path;
  const TrajectoryResult r = AnalyzeTrajectory(track, options);
  s.flights = static_cast<int>(r.flights.size());
  for (bool o : r.outlier) s.outliers += o;
  s.restitution = s.friction = kNaN;
  for (const auto& b : r.breaks) {
    s.bounces += b.kind == FlightEvent::kBounce;
    s.hits += b.kind == FlightEvent::kHit;
    if (b.kind == FlightEvent::kBounce && b.bounce.ok && !std::isfinite(s.restitution)) {
      s.restitution = b.bounce.restitution;
      s.friction = b.bounce.friction;
    }
  }
  const Flight* pre = nullptr;
  const Flight* post = nullptr;
  for (size_t i = 0; i < r.flights.size(); ++i) {
    if (r.flights[i].end_event == FlightEvent::kBounce) {
      pre = &r.flights[i];
      if (i + 1 < r.flights.size()) post = &r.flights[i + 1];
      break;
    }
  }
  if (pre == nullptr) return s;
  std::vector<BallSample> seen;
  for (int k : pre->samples) {
    if (!r.outlier[k]) seen.push_back(track[k]);
  }
  if (seen.size() < 8) return s;
  s.scored = true;
  s.model = FlightModelName(pre->model_kind());
  s.rmse_gravity_m = RmseOr(pre->no_drag);
  s.rmse_drag_m = RmseOr(pre->with_drag);
  s.rmse_spin_m = RmseOr(pre->with_spin);
  s.rmse_free_m = pre->free_accel.ok ? pre->free_accel.rmse_m : kNaN;
  s.rmse_chosen_m = pre->rmse_m;
  s.spin_revps = pre->spin_used ? pre->model().SpinRevPerS() : 0.0;
  // The reference bounce: a free constant-acceleration fit of the last samples before the
  // contact, where it descends through the bounce height.
  const double zr = options.ground_z_m + options.ball_radius_m;
  std::vector<BallSample> last;
  for (const auto& b : seen) {
    if (b.time_s >= seen.back().time_s - eval.reference_window_s) last.push_back(b);
  }
  const ConstantAccelerationFit ref = FitConstantAcceleration(last);
  const auto t_ref = ref.ok ? ref.DescendingCrossing(zr, last.front().time_s) : std::nullopt;
  if (!t_ref) {
    s.scored = false;
    return s;
  }
  const Eigen::Vector2d bounce_xy = ref.PositionAt(*t_ref).head<2>();
  // The first part of the seen span.
  const double t_cut =
      seen.front().time_s + eval.prediction_fraction * (*t_ref - seen.front().time_s);
  std::vector<BallSample> first;
  for (const auto& b : seen) {
    if (b.time_s <= t_cut) first.push_back(b);
  }
  auto err = [&](const LandingPrediction& p) {
    return p.ok ? (p.landing_m.head<2>() - bounce_xy).norm() : kNaN;
  };
  s.pred_chosen_m = err(
      PredictLanding(first, PredictionModel(*pre, first, options, r.noise_m), options, r.noise_m));
  s.pred_drag_m = err(PredictLanding(first, FlightModel::kDrag, options, r.noise_m));
  s.pred_spin_m = err(PredictLanding(first, FlightModel::kSpin, options, r.noise_m));
  const ConstantAccelerationFit fa = FitConstantAcceleration(first);
  const auto tf = fa.ok ? fa.DescendingCrossing(zr, first.back().time_s) : std::nullopt;
  s.pred_free_m = tf ? (fa.PositionAt(*tf).head<2>() - bounce_xy).norm() : kNaN;
  // The flight after the bounce from the flight before it and the bounce model.
  s.after_bounce_rmse_m = kNaN;
  if (post != nullptr && post->start_event == FlightEvent::kBounce) {
    const BallisticModel& m = pre->model();
    const auto tc = m.CrossingTime(zr, seen.back().time_s, true, 1.0);
    if (tc) {
      BallisticModel after = m;
      after.t0_s = *tc;
      m.StateAt(*tc, &after.p0_m, &after.v0_mps);
      options.bounce.Apply(options.ball_radius_m, &after.v0_mps, &after.spin_radps);
      double ss = 0;
      int n = 0;
      for (int k : post->samples) {
        if (r.outlier[k] || track[k].time_s > *tc + 0.1) continue;
        ss += (after.PositionAt(track[k].time_s) - track[k].ball_in_world).squaredNorm();
        ++n;
      }
      if (n > 0) s.after_bounce_rmse_m = std::sqrt(ss / n);
    }
  }
  return s;
}

BounceTrackSummary Summarize(std::vector<BounceTrackScore> tracks) {
  BounceTrackSummary out;
  out.tracks = std::move(tracks);
  using S = BounceTrackScore;
  out.median_rmse_gravity_m = MedianFinite(out.tracks, &S::rmse_gravity_m);
  out.median_rmse_drag_m = MedianFinite(out.tracks, &S::rmse_drag_m);
  out.median_rmse_spin_m = MedianFinite(out.tracks, &S::rmse_spin_m);
  out.median_rmse_free_m = MedianFinite(out.tracks, &S::rmse_free_m);
  out.median_rmse_chosen_m = MedianFinite(out.tracks, &S::rmse_chosen_m);
  out.median_pred_chosen_m = MedianFinite(out.tracks, &S::pred_chosen_m);
  out.median_pred_drag_m = MedianFinite(out.tracks, &S::pred_drag_m);
  out.median_pred_spin_m = MedianFinite(out.tracks, &S::pred_spin_m);
  out.median_pred_free_m = MedianFinite(out.tracks, &S::pred_free_m);
  out.median_after_bounce_rmse_m = MedianFinite(out.tracks, &S::after_bounce_rmse_m);
  out.median_restitution = MedianFinite(out.tracks, &S::restitution);
  out.median_friction = MedianFinite(out.tracks, &S::friction);
  for (const auto& t : out.tracks) {
    out.one_bounce += t.bounces == 1;
    out.spin_chosen += t.scored && t.model == "spin";
  }
  return out;
}

std::string BounceTrackSummary::Table() const {
  auto mm = [](double v) { return std::isfinite(v) ? fmt::format("{:.1f}", v * 1e3) : "-"; };
  auto cm = [](double v) { return std::isfinite(v) ? fmt::format("{:.1f}", v * 1e2) : "-"; };
  std::string s = fmt::format(
      "{:<10} {:>3} {:>3} {:>3} {:>7} | pre-bounce rmse mm: {:>6} {:>6} {:>6} {:>6} {:>6} | "
      "landing from first half cm: {:>6} {:>6} {:>6} {:>6} | {:>6} {:>8}\n",
      "track", "bnc", "hit", "out", "model", "chosen", "grav", "drag", "spin", "free", "chosen",
      "drag", "spin", "free", "rev/s", "after_mm");
  for (const auto& t : tracks) {
    std::string name = t.path;
    if (const auto p = name.find_last_of('/'); p != std::string::npos) name = name.substr(p + 1);
    if (!t.scored) {
      s += fmt::format("{:<10} {:>3} {:>3} {:>3}  (no fitted flight ending in a bounce)\n", name,
                       t.bounces, t.hits, t.outliers);
      continue;
    }
    s += fmt::format(
        "{:<10} {:>3} {:>3} {:>3} {:>7} | {:>26} {:>6} {:>6} {:>6} {:>6} | {:>34} {:>6} {:>6} "
        "{:>6} | {:>6.0f} {:>8}\n",
        name, t.bounces, t.hits, t.outliers, t.model, mm(t.rmse_chosen_m), mm(t.rmse_gravity_m),
        mm(t.rmse_drag_m), mm(t.rmse_spin_m), mm(t.rmse_free_m), cm(t.pred_chosen_m),
        cm(t.pred_drag_m), cm(t.pred_spin_m), cm(t.pred_free_m), t.spin_revps,
        mm(t.after_bounce_rmse_m));
  }
  s += fmt::format(
      "median over {} tracks ({} with exactly one bounce, spin chosen on {}): pre-bounce rmse "
      "chosen {} mm, gravity {} mm, drag {} mm, spin {} mm, free constant acceleration {} mm; "
      "landing from the first half: chosen {} cm, drag {} cm, spin {} cm, free {} cm; after the "
      "bounce (first 0.1 s, predicted with the default bounce model) {} mm; bounces measured: "
      "restitution {:.2f}, friction {:.2f} (medians)\n",
      tracks.size(), one_bounce, spin_chosen, mm(median_rmse_chosen_m), mm(median_rmse_gravity_m),
      mm(median_rmse_drag_m), mm(median_rmse_spin_m), mm(median_rmse_free_m),
      cm(median_pred_chosen_m), cm(median_pred_drag_m), cm(median_pred_spin_m),
      cm(median_pred_free_m), mm(median_after_bounce_rmse_m), median_restitution, median_friction);
  return s;
}

}  // namespace fv::recon
