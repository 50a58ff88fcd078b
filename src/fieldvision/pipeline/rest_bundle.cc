#include "fieldvision/pipeline/rest_bundle.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <fmt/format.h>

#include "fieldvision/pipeline/detections_job.h"
#include "fieldvision/recon/triangulation.h"
#include "fieldvision/util/error.h"

namespace fv::pipeline {

void RestBundleOptions::Check() const {
  auto positive = [](double v, const char* name) {
    FV_REQUIRE(std::isfinite(v) && v > 0, "RestBundleOptions.{} must be > 0 (got {})", name, v);
  };
  positive(tolerance_m, "tolerance_m");
  positive(max_drift_m, "max_drift_m");
  positive(max_gap_s, "max_gap_s");
  positive(gate_px, "gate_px");
  FV_REQUIRE(std::isfinite(min_duration_s) && min_duration_s >= 0,
             "RestBundleOptions.min_duration_s must be >= 0 (got {})", min_duration_s);
  FV_REQUIRE(min_frames >= 2, "RestBundleOptions.min_frames must be >= 2 (got {})", min_frames);
  FV_REQUIRE(max_frames_per_camera >= 1,
             "RestBundleOptions.max_frames_per_camera must be >= 1 (got {})",
             max_frames_per_camera);
}

namespace {

// Running sums of a run's positions over time (t from the run's start) for its mean and the
// least-squares line through it.
class RunFit {
 public:
  explicit RunFit(double t0_s) : t0_s_(t0_s) {}
  void Add(double t_s, const Eigen::Vector3d& p) {
    const double t = t_s - t0_s_;
    ++n_;
    st_ += t;
    stt_ += t * t;
    sp_ += p;
    spp_ += p.squaredNorm();
    stp_ += t * p;
    t_last_ = t;
  }
  int n() const { return n_; }
  Eigen::Vector3d Mean() const { return sp_ / n_; }
  // Whether the fitted line moves more than max_drift_m over the run and more than four
  // standard errors of that motion (from the positions' scatter about the line, judged from
  // min_samples on: fewer scatter too little to tell): a few noisy positions of a still ball
  // fit a line that moves by their noise. Before that the tolerance alone holds a run together.
  bool Drifts(double max_drift_m, int min_samples) const {
    const double var_t = stt_ - st_ * st_ / n_;
    if (n_ < std::max(min_samples, 4) || var_t <= 1e-12) return false;
    const Eigen::Vector3d v = (stp_ - st_ * sp_ / n_) / var_t;
    const double drift = v.norm() * t_last_;
    const double scatter = std::max(spp_ - sp_.squaredNorm() / n_ - v.squaredNorm() * var_t, 0.0);
    const double sigma_m = std::sqrt(scatter / (3.0 * (n_ - 2)));  // per axis
    const double sigma_drift = sigma_m / std::sqrt(var_t) * t_last_;
    return drift > max_drift_m && drift > 4.0 * sigma_drift;
  }

 private:
  double t0_s_, t_last_ = 0.0, st_ = 0.0, stt_ = 0.0, spp_ = 0.0;
  Eigen::Vector3d sp_ = Eigen::Vector3d::Zero(), stp_ = Eigen::Vector3d::Zero();
  int n_ = 0;
};

// The run starting at `first` (not skipped): grown while the next row is close in time, lies
// within tolerance of the run's mean and the run does not drift (RunFit::Drifts).
size_t GrowRun(const std::vector<recon::BallSample>& track, const std::vector<char>& skip,
               size_t first, const RestBundleOptions& o) {
  RunFit fit(track[first].time_s);
  fit.Add(track[first].time_s, track[first].ball_in_world);
  size_t last = first;
  for (size_t j = first + 1; j < track.size(); ++j) {
    if ((!skip.empty() && skip[j]) || track[j].time_s - track[j - 1].time_s > o.max_gap_s ||
        (track[j].ball_in_world - fit.Mean()).norm() > o.tolerance_m) {
      break;
    }
    RunFit grown = fit;
    grown.Add(track[j].time_s, track[j].ball_in_world);
    if (grown.Drifts(o.max_drift_m, o.min_frames)) break;
    fit = grown;
    last = j;
  }
  return last;
}

// Each camera's non-weak candidate nearest the point's image in the frames of [t0, t1] (within
// margin), within max(gate_px, half the candidate's radius); at most max_frames frames a camera,
// evenly spread (a ball resting for minutes adds nothing past a few seconds but work).
std::vector<recon::View> GatherViews(const std::vector<camera::Camera>& cameras,
                                     const std::vector<std::vector<CameraMessage>>& messages,
                                     const Eigen::Vector3d& point, double t0_s, double t1_s,
                                     double margin_s, double gate_px, int max_frames) {
  std::vector<recon::View> views;
  for (size_t c = 0; c < messages.size() && c < cameras.size(); ++c) {
    const auto uv = recon::PredictBallCentre(cameras[c], point, 0.0);
    if (!uv) continue;
    const auto in_run = [&](const CameraMessage& m) {
      return m.time_s >= t0_s - margin_s && m.time_s <= t1_s + margin_s;
    };
    const auto count = std::count_if(messages[c].begin(), messages[c].end(), in_run);
    const long stride = std::max<long>(1, (count + max_frames - 1) / max_frames);
    long k = 0;
    for (const CameraMessage& m : messages[c]) {
      if (!in_run(m) || k++ % stride != 0) continue;
      const recon::BallObservation* best = nullptr;
      double best_d = 0.0;
      for (const recon::BallObservation& o : m.candidates) {
        const double d = (o.centre_px - *uv).norm();
        if (o.weak || d > std::max(gate_px, 0.5 * o.radius_px)) continue;
        if (best == nullptr || d < best_d) best = &o, best_d = d;
      }
      if (best != nullptr) views.push_back({static_cast<int>(c), *best});
    }
  }
  return views;
}

int DistinctCameras(const std::vector<recon::View>& views) {
  std::set<int> cams;
  for (const recon::View& v : views) cams.insert(v.camera);
  return static_cast<int>(cams.size());
}

// The point of the views, refitted without those it explains far worse than the rest, up to
// three times; not ok with fewer than two cameras left.
recon::TriangulationResult TrimmedPoint(const std::vector<camera::Camera>& cameras,
                                        std::vector<recon::View> views,
                                        const recon::TriangulationOptions& topt) {
  recon::TriangulationResult r = recon::TriangulatePoint(cameras, views, topt);
  for (int round = 0; round < 3 && r.ok(); ++round) {
    // (r.views is in camera order, not the views' order: measured here.)
    std::vector<double> dist;
    for (const recon::View& v : views) {
      const auto uv = recon::PredictBallCentre(cameras[v.camera], r.point_world, 0.0);
      dist.push_back(uv ? (*uv - v.observation.centre_px).norm()
                        : std::numeric_limits<double>::infinity());
    }
    const double limit = CandidateOutlierLimitPx(dist);
    std::vector<recon::View> kept;
    for (size_t i = 0; i < views.size(); ++i) {
      if (dist[i] <= limit) kept.push_back(views[i]);
    }
    if (kept.size() == views.size()) break;
    if (DistinctCameras(kept) < 2) {
      r.status = recon::TriangulationStatus::kTooFewViews;
      break;
    }
    views = std::move(kept);
    r = recon::TriangulatePoint(cameras, views, topt);
  }
  return r;
}

}  // namespace

std::string RestBundle::Summary(const std::string& views) const {
  if (runs == 0) return "";
  return fmt::format("{} resting ball{} refined on {} ({} rows, {:.2f} px RMS)", runs,
                     runs == 1 ? "" : "s", views, rows, rms_px);
}

std::vector<RestRun> FindRestingRuns(const std::vector<recon::BallSample>& track,
                                     const std::vector<char>& skip, const RestBundleOptions& o) {
  o.Check();
  FV_REQUIRE(skip.empty() || skip.size() == track.size(),
             "FindRestingRuns: {} skip flags for {} rows", skip.size(), track.size());
  std::vector<RestRun> runs;
  for (size_t i = 0; i < track.size();) {
    if (!skip.empty() && skip[i]) {
      ++i;
      continue;
    }
    const size_t last = GrowRun(track, skip, i, o);
    if (static_cast<int>(last - i + 1) >= o.min_frames &&
        track[last].time_s - track[i].time_s >= o.min_duration_s) {
      runs.push_back({i, last});
    }
    i = last + 1;
  }
  return runs;
}

RestBundle BundleRests(const std::vector<camera::Camera>& cameras,
                       const std::vector<std::vector<CameraMessage>>& messages,
                       double ball_radius_m, double margin_s, const std::vector<char>& skip,
                       const RestBundleOptions& options, std::vector<recon::BallSample>* track) {
  FV_REQUIRE(track != nullptr, "BundleRests: no track");
  RestBundle out;
  recon::TriangulationOptions topt;
  topt.ball_radius_m = ball_radius_m;
  double ss = 0.0;
  for (const RestRun& run : FindRestingRuns(*track, skip, options)) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (size_t i = run.first; i <= run.last; ++i) mean += (*track)[i].ball_in_world;
    mean /= static_cast<double>(run.last - run.first + 1);
    const std::vector<recon::View> views =
        GatherViews(cameras, messages, mean, (*track)[run.first].time_s, (*track)[run.last].time_s,
                    margin_s, options.gate_px, options.max_frames_per_camera);
    if (DistinctCameras(views) < 2) continue;
    const recon::TriangulationResult r = TrimmedPoint(cameras, views, topt);
    // A point that left the run (a bad set of views) is no refinement of it.
    if (!r.ok() || (r.point_world - mean).norm() > options.tolerance_m) continue;
    ++out.runs;
    out.observations += r.num_views();
    ss += r.rms_px * r.rms_px * r.num_views();
    for (size_t i = run.first; i <= run.last; ++i) {
      (*track)[i].ball_in_world = r.point_world;
      (*track)[i].err_px = r.rms_px;
      ++out.rows;
    }
  }
  if (out.observations > 0) out.rms_px = std::sqrt(ss / static_cast<double>(out.observations));
  return out;
}

}  // namespace fv::pipeline
