#include "fieldvision/pipeline/detections_job.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>

#include <fmt/format.h>

#include <ceres/ceres.h>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/camera/projection.h"
#include "fieldvision/pipeline/ball_job.h"
#include "fieldvision/pipeline/ball_pipeline.h"
#include "fieldvision/pipeline/fusion_stage.h"
#include "fieldvision/pipeline/rest_bundle.h"
#include "fieldvision/recon/ball_csv.h"
#include "fieldvision/recon/standard_balls.h"
#include "fieldvision/recon/trajectory_io.h"
#include "fieldvision/recon/trajectory_path.h"
#include "fieldvision/recon/trajectory_physics.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/stats.h"

namespace fv::pipeline {

void DetectionsJobOptions::Check() const {
  FV_REQUIRE(!cameras.empty(), "ball: give at least one --camera and --detections pair");
  FV_REQUIRE(cameras.size() == detections.size(),
             "ball: {} --camera but {} --detections (they pair up)", cameras.size(),
             detections.size());
  FV_REQUIRE(cameras.size() >= 2 || triangulation.single_camera_ground,
             "ball: one camera gives no 3D position: give 2 or more --camera/--detections pairs "
             "(or --ground for positions on the ground)");
  FV_REQUIRE(std::isfinite(ball_diameter_m) && ball_diameter_m > 0 && ball_diameter_m < 2,
             "ball: --ball-diameter must be in (0, 2) metres (got {})", ball_diameter_m);
  FV_REQUIRE(std::isfinite(sigma_px) && sigma_px > 0, "ball: --det-sigma must be > 0 (got {})",
             sigma_px);
  FV_REQUIRE(std::isfinite(tolerance_s) && tolerance_s > 0,
             "ball: --tolerance must be > 0 (got {})", tolerance_s);
  FV_REQUIRE(!out.empty(), "ball: --out is required");
  triangulation.Check();
  eval.Check();
}

double CandidateOutlierLimitPx(const std::vector<double>& dist_px) {
  const double sigma = util::NearestRankPercentile(dist_px, 0.5) / 1.1774;
  return std::max(4.0 * sigma, 0.5);
}

std::vector<CameraMessage> ParseDetections(const util::CsvTable& t, int camera, double sigma_px) {
  t.Require({"frame", "time_s", "u", "v"});
  const bool has_r = t.Has("radius_px"), has_score = t.Has("score");
  std::vector<CameraMessage> out;
  for (size_t r = 0; r < t.rows(); ++r) {
    const long long frame = t.GetInt(r, "frame");
    const double time_s = t.GetDouble(r, "time_s");
    FV_REQUIRE(std::isfinite(time_s), "{}: time_s is not finite", t.Where(r));
    if (out.empty() || out.back().frame != frame) {
      if (!out.empty()) {
        FV_REQUIRE(frame > out.back().frame && time_s > out.back().time_s,
                   "{}: frame {} at {} s does not follow frame {} at {} s (frames and times must "
                   "increase; rows of one frame together)",
                   t.Where(r), frame, time_s, out.back().frame, out.back().time_s);
      }
      CameraMessage m;
      m.camera = camera;
      m.frame = frame;
      m.time_s = time_s;
      out.push_back(m);
    } else {
      FV_REQUIRE(time_s == out.back().time_s, "{}: frame {} has two times ({} and {} s)",
                 t.Where(r), frame, out.back().time_s, time_s);
    }
    // Empty u and v: a frame without a detection.
    if (t.Get(r, "u").empty() && t.Get(r, "v").empty()) continue;
    recon::BallObservation o;
    o.centre_px = {t.GetDouble(r, "u"), t.GetDouble(r, "v")};
    FV_REQUIRE(o.centre_px.allFinite(), "{}: u, v are not finite", t.Where(r));
    o.sigma_px = sigma_px;
    if (has_r && !t.Get(r, "radius_px").empty()) {
      o.radius_px = t.GetDouble(r, "radius_px");
      FV_REQUIRE(std::isfinite(o.radius_px) && o.radius_px >= 0,
                 "{}: radius_px must be a number >= 0", t.Where(r));
    }
    if (has_score && !t.Get(r, "score").empty()) {
      o.score = t.GetDouble(r, "score");
      FV_REQUIRE(std::isfinite(o.score), "{}: score is not finite", t.Where(r));
    }
    out.back().candidates.push_back(o);
  }
  FV_REQUIRE(!out.empty(), "detections '{}': no rows", t.name());
  for (auto& m : out) {
    std::stable_sort(m.candidates.begin(), m.candidates.end(),
                     [](const recon::BallObservation& a, const recon::BallObservation& b) {
                       return a.score > b.score;
                     });
  }
  return out;
}

std::vector<CameraMessage> ReadDetectionsCsv(const std::string& path, int camera, double sigma_px) {
  FV_REQUIRE(std::filesystem::exists(path), "detections file '{}' does not exist", path);
  return ParseDetections(util::CsvTable::Read(path), camera, sigma_px);
}

namespace {

// A per-frame position this close to a flight's model lies on it (farther: 0.5 m off).
constexpr double kNearM = 0.5;

struct Bundled {
  bool ok = false;
  recon::FlightModel kind = recon::FlightModel::kGravity;
  recon::BallisticModel model;
  double rms_px = 0.0;
  int observations = 0;
  // Over the observations at the times of per-frame positions: the model's RMS and theirs.
  double model_rms_at_frames_px = 0.0;
  double frames_rms_px = 0.0;
  int at_frames = 0;
  // Per-frame positions within the flight's seen span, and those near the model (kNearM).
  int span_frames = 0;
  int near_frames = 0;
  // Per per-frame position (index into the per-frame track) with candidates at its moment: the
  // RMS distance of each camera's candidate nearest the model's image, and nearest its own.
  struct AtFrame {
    double model_ss = 0.0, frame_ss = 0.0;
    int n = 0;
    double model_rms() const { return std::sqrt(model_ss / n); }
    double frame_rms() const { return std::sqrt(frame_ss / n); }
  };
  std::map<size_t, AtFrame> at_frame;
};

// A candidate of a flight's bundle.
struct FlightObservation {
  int cam;
  Eigen::Vector2d uv;
  double time_s;
};

// The per-frame position nearest `time_s` within margin_s (end: none).
std::vector<recon::BallSample>::const_iterator NearestSample(
    const std::vector<recon::BallSample>& per_frame, double time_s, double margin_s) {
  auto at = std::lower_bound(per_frame.begin(), per_frame.end(), time_s,
                             [](const recon::BallSample& s, double t) { return s.time_s < t; });
  if (at != per_frame.begin() &&
      (at == per_frame.end() || time_s - std::prev(at)->time_s < at->time_s - time_s)) {
    --at;
  }
  if (at == per_frame.end() || std::abs(at->time_s - time_s) > std::max(margin_s, 1e-6)) {
    return per_frame.end();
  }
  return at;
}

// Per frame of the flight's span, every camera's candidate nearest the model's image and the one
// nearest the frame's own position's image (no gate: a moment the model does not follow has its
// candidates far from it): both distances, into out->at_frame.
void FitAtFrames(const std::vector<camera::Camera>& cameras,
                 const std::vector<std::vector<CameraMessage>>& messages,
                 const std::vector<recon::BallSample>& per_frame, double margin_s, double t_first_s,
                 double t_last_s, Bundled* out) {
  const auto nearest = [](const CameraMessage& m, const Eigen::Vector2d& uv) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& o : m.candidates) best = std::min(best, (o.centre_px - uv).squaredNorm());
    return best;
  };
  for (size_t c = 0; c < messages.size(); ++c) {
    for (const CameraMessage& m : messages[c]) {
      if (m.candidates.empty() || m.time_s < t_first_s - margin_s ||
          m.time_s > t_last_s + margin_s) {
        continue;
      }
      const auto at = NearestSample(per_frame, m.time_s, margin_s);
      if (at == per_frame.end()) continue;
      const auto uv_model = cameras[c].Project(out->model.PositionAt(m.time_s));
      const auto uv_frame = cameras[c].Project(at->ball_in_world);
      if (!uv_model || !uv_frame) continue;
      Bundled::AtFrame& a = out->at_frame[static_cast<size_t>(at - per_frame.begin())];
      a.model_ss += nearest(m, *uv_model);
      a.frame_ss += nearest(m, *uv_frame);
      ++a.n;
    }
  }
}

// A flight is fitted on at least this many reprojection residuals (two per candidate): the
// gravity model's 6 parameters and 4 more.
constexpr int kMinResiduals = 6 + 4;

constexpr int kTrimRounds = 3;

// The bundled model against each frame's own position on the observations at the frames'
// moments (the nearest per-frame position within half a frame, margin_s): both RMS, without
// the candidates their own frames' positions explain far worse than the rest
// (CandidateOutlierLimitPx): those are the detector's errors, not the model's.
void CompareWithFrames(const std::vector<camera::Camera>& cameras,
                       const std::vector<FlightObservation>& obs,
                       const std::vector<recon::BallSample>& per_frame, double margin_s,
                       double t_first_s, double t_last_s, Bundled* out) {
  std::vector<double> d_model, d_frame;
  for (const auto& o : obs) {
    const auto at = NearestSample(per_frame, o.time_s, margin_s);
    if (at == per_frame.end()) continue;
    const auto uv_model = cameras[o.cam].Project(out->model.PositionAt(o.time_s));
    const auto uv_frame = cameras[o.cam].Project(at->ball_in_world);
    if (!uv_model || !uv_frame) continue;
    d_model.push_back((*uv_model - o.uv).norm());
    d_frame.push_back((*uv_frame - o.uv).norm());
  }
  const double limit = d_frame.empty() ? 0.0 : CandidateOutlierLimitPx(d_frame);
  double ss_model = 0, ss_frames = 0;
  for (size_t i = 0; i < d_frame.size(); ++i) {
    if (d_frame[i] > limit) continue;
    ss_model += d_model[i] * d_model[i];
    ss_frames += d_frame[i] * d_frame[i];
    ++out->at_frames;
  }
  for (const recon::BallSample& s : per_frame) {
    if (s.time_s < t_first_s - 1e-9 || s.time_s > t_last_s + 1e-9) continue;
    ++out->span_frames;
    out->near_frames += (out->model.PositionAt(s.time_s) - s.ball_in_world).norm() <= kNearM;
  }
  if (out->at_frames > 0) {
    out->model_rms_at_frames_px = std::sqrt(ss_model / out->at_frames);
    out->frames_rms_px = std::sqrt(ss_frames / out->at_frames);
  }
}

// The candidate of each camera's message in the flight's span nearest the model's image of
// the ball (within a gate).
std::vector<FlightObservation> GatherObservations(
    const std::vector<camera::Camera>& cameras,
    const std::vector<std::vector<CameraMessage>>& messages, const recon::Flight& f,
    const recon::BallisticModel& start, double gate_px, double margin_s) {
  std::vector<FlightObservation> obs;
  for (size_t c = 0; c < messages.size(); ++c) {
    for (const auto& m : messages[c]) {
      if (m.time_s < f.t_first_seen_s - margin_s || m.time_s > f.t_last_seen_s + margin_s) continue;
      const auto pred = cameras[c].Project(start.PositionAt(m.time_s));
      if (!pred) continue;
      const recon::BallObservation* best = nullptr;
      double best_d = gate_px;
      for (const auto& o : m.candidates) {
        const double d = (o.centre_px - *pred).norm();
        if (d < best_d) best_d = d, best = &o;
      }
      if (best) obs.push_back({static_cast<int>(c), best->centre_px, m.time_s});
    }
  }
  return obs;
}

// A flight model's parameters during the fit (BallisticModel's, with c_M w for the spin).
struct FlightParams {
  double p0[3], v0[3], k[1], sm[3];
  double bic = 0.0;
  recon::FlightModel kind = recon::FlightModel::kGravity;
};

// Fits one model to the observations from `x` (in place); false when Ceres gives up.
bool SolveFlightModel(const std::vector<camera::Camera>& cameras,
                      const std::vector<FlightObservation>& obs, recon::FlightModel m,
                      const recon::TrajectoryOptions& to, double sigma_px, double t_ref,
                      FlightParams* x, double* cost) {
  std::vector<double> dt_s;
  dt_s.reserve(obs.size());
  for (const auto& o : obs) dt_s.push_back(o.time_s - t_ref);
  // The drag and spin models' path, integrated once per evaluation for all observations.
  std::unique_ptr<recon::FlightPath> path;
  if (m != recon::FlightModel::kGravity) {
    path = std::make_unique<recon::FlightPath>(dt_s, to.gravity_mps2);
  }
  ceres::Problem problem;
  for (size_t i = 0; i < obs.size(); ++i) {
    problem.AddResidualBlock(
        new recon::FlightReprojection(path.get(), static_cast<int>(i), dt_s[i], to.gravity_mps2,
                                      cameras[obs[i].cam], obs[i].uv, sigma_px),
        new ceres::HuberLoss(2.0), x->p0, x->v0, x->k, x->sm);
  }
  if (m == recon::FlightModel::kGravity) {
    problem.SetParameterBlockConstant(x->k);
  } else {
    problem.SetParameterLowerBound(x->k, 0, 0.0);
    problem.SetParameterUpperBound(x->k, 0, to.max_drag_per_m);
  }
  if (m == recon::FlightModel::kSpin) {
    const double unit = 1.0 / (to.MagnusPerRad() * 2 * M_PI);
    const Eigen::Vector3d d = Eigen::Vector3d(x->v0[0], x->v0[1], x->v0[2]).normalized();
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<recon::SpinPrior, 3, 3>(
            new recon::SpinPrior(d, unit / to.spin_prior_revps, unit / to.spin_along_prior_revps)),
        nullptr, x->sm);
  } else {
    problem.SetParameterBlockConstant(x->sm);
  }
  ceres::Solver::Options so;
  so.max_num_iterations = 50;
  so.linear_solver_type = ceres::DENSE_QR;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  *cost = summary.final_cost;
  return summary.IsSolutionUsable();
}

// Each model in turn from the one before (gravity, drag, spin), starting from `start`; the more
// complex one is kept when its BIC over the 2 n reprojection residuals (in sigmas) is lower by
// spin_min_bic_gain.
std::optional<FlightParams> SelectFlightModel(const std::vector<camera::Camera>& cameras,
                                              const std::vector<FlightObservation>& obs,
                                              const FlightParams& start,
                                              const recon::TrajectoryOptions& to, double sigma_px,
                                              double t_ref) {
  FlightParams x = start;
  const double nres = 2.0 * obs.size();
  std::optional<FlightParams> best;
  for (recon::FlightModel m :
       {recon::FlightModel::kGravity, recon::FlightModel::kDrag, recon::FlightModel::kSpin}) {
    const int params = m == recon::FlightModel::kGravity ? 6
                       : m == recon::FlightModel::kDrag  ? 7
                                                         : 10;
    if (nres < params + 4) break;
    if (m != recon::FlightModel::kSpin) x.sm[0] = x.sm[1] = x.sm[2] = 0.0;
    if (m == recon::FlightModel::kGravity) x.k[0] = 0.0;
    double cost = 0;
    if (!SolveFlightModel(cameras, obs, m, to, sigma_px, t_ref, &x, &cost)) break;
    x.bic = nres * std::log(std::max(2 * cost, 1e-12) / nres) + params * std::log(nres);
    x.kind = m;
    if (!best ||
        x.bic < best->bic - (m == recon::FlightModel::kGravity ? 0.0 : to.spin_min_bic_gain)) {
      best = x;
    }
  }
  return best;
}

// The flight model the parameters stand for (the rest of it, its time origin, from `start`).
recon::BallisticModel ModelOf(const FlightParams& x, const recon::BallisticModel& start,
                              double c_m) {
  recon::BallisticModel model = start;
  model.p0_m = {x.p0[0], x.p0[1], x.p0[2]};
  model.v0_mps = {x.v0[0], x.v0[1], x.v0[2]};
  model.drag_per_m = x.kind == recon::FlightModel::kGravity ? 0.0 : x.k[0];
  model.magnus_per_rad = x.kind == recon::FlightModel::kSpin ? c_m : 0.0;
  model.spin_radps = x.kind == recon::FlightModel::kSpin
                         ? Eigen::Vector3d(Eigen::Vector3d(x.sm[0], x.sm[1], x.sm[2]) / c_m)
                         : Eigen::Vector3d::Zero();
  return model;
}

// The observations the model explains within CandidateOutlierLimitPx of their distances,
// refitted up to kTrimRounds times: a centre a few pixels off (a fit to the ball and its shadow,
// a frame's wrong candidate) is inside the Huber loss's quadratic zone at the detections'
// nominal sigma, and at a flight's ends it tilts the velocity (low-sun kick render, seed 3: the
// last 11 frames drifted to 15 mm).
std::vector<FlightObservation> TrimObservations(const std::vector<camera::Camera>& cameras,
                                                const std::vector<FlightObservation>& obs,
                                                const recon::BallisticModel& model) {
  std::vector<double> dist(obs.size(), std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < obs.size(); ++i) {
    const auto uv = cameras[obs[i].cam].Project(model.PositionAt(obs[i].time_s));
    if (uv) dist[i] = (*uv - obs[i].uv).norm();
  }
  const double limit = CandidateOutlierLimitPx(dist);
  std::vector<FlightObservation> kept;
  for (size_t i = 0; i < obs.size(); ++i) {
    if (dist[i] <= limit) kept.push_back(obs[i]);
  }
  return kept;
}

// The flight's model refitted on the detections of every camera between its first and last
// seen samples (the candidate nearest the model's prediction, within a gate), then again without
// the candidates it explains far worse than the rest (TrimObservations), up to kTrimRounds times.
Bundled BundleFlight(const std::vector<camera::Camera>& cameras,
                     const std::vector<std::vector<CameraMessage>>& messages,
                     const recon::Flight& f, const recon::TrajectoryOptions& to, double sigma_px,
                     double margin_s, const std::vector<recon::BallSample>& per_frame) {
  Bundled out;
  const recon::BallisticModel start = f.model();
  const recon::FlightModel kind = f.model_kind();  // of the fit to the per-frame points
  const double t_ref = start.t0_s;
  const std::vector<FlightObservation> gathered =
      GatherObservations(cameras, messages, f, start, 5 * sigma_px + 10.0, margin_s);
  if (static_cast<int>(gathered.size()) * 2 < kMinResiduals) return out;
  std::vector<FlightObservation> obs = gathered;
  const double c_m = to.MagnusPerRad();
  const Eigen::Vector3d s0 = start.magnus_per_rad * start.spin_radps;
  const FlightParams initial{{start.p0_m.x(), start.p0_m.y(), start.p0_m.z()},
                             {start.v0_mps.x(), start.v0_mps.y(), start.v0_mps.z()},
                             {kind == recon::FlightModel::kGravity ? 0.0 : start.drag_per_m},
                             {s0.x(), s0.y(), s0.z()}};
  std::optional<FlightParams> best = SelectFlightModel(cameras, obs, initial, to, sigma_px, t_ref);
  if (!best) return out;
  for (int round = 0; round < kTrimRounds; ++round) {
    std::vector<FlightObservation> kept =
        TrimObservations(cameras, obs, ModelOf(*best, start, c_m));
    if (kept.size() == obs.size() || static_cast<int>(kept.size()) * 2 < kMinResiduals) break;
    auto again = SelectFlightModel(cameras, kept, initial, to, sigma_px, t_ref);
    if (!again) break;
    best = again;
    obs = std::move(kept);
  }
  out.model = ModelOf(*best, start, c_m);
  out.kind = best->kind;
  double ss = 0;
  for (const auto& o : obs) {
    const auto uv = cameras[o.cam].Project(out.model.PositionAt(o.time_s));
    if (uv) ss += (*uv - o.uv).squaredNorm();
  }
  out.observations = static_cast<int>(obs.size());
  out.rms_px = std::sqrt(ss / obs.size());
  CompareWithFrames(cameras, gathered, per_frame, margin_s, f.t_first_seen_s, f.t_last_seen_s,
                    &out);
  FitAtFrames(cameras, messages, per_frame, margin_s, f.t_first_seen_s, f.t_last_seen_s, &out);
  out.ok = out.model.p0_m.allFinite() && out.model.v0_mps.allFinite();
  return out;
}

// The flight model's options for a ball of this size (mass 0: the standard ball's nearest in
// diameter).
recon::TrajectoryOptions FlightOptions(double ball_diameter_m, double ball_mass_kg) {
  recon::TrajectoryOptions to;
  to.ball_radius_m = 0.5 * ball_diameter_m;
  to.ball_mass_kg =
      ball_mass_kg > 0 ? ball_mass_kg : recon::NearestStandardBall(ball_diameter_m).mass_kg;
  return to;
}

}  // namespace

// A flight's model is kept when its RMS at the frames' moments is at most this times theirs plus
// this many pixels, and when at least kMinNearShare of the per-frame positions in its span lie
// within kNearM of it: a "flight" through two places where the ball rested, taking the positions
// between as outliers, passes candidates of other objects on its way and its RMS alone can look
// good.
constexpr double kMaxModelRmsRatio = 2.5;
constexpr double kModelRmsSlackPx = 0.3;
constexpr double kMinNearShare = 0.8;

// A frame keeps its own position inside a refined flight where the model explains that frame's
// candidates much worse than both the flight's typical frame (the median of the frames' model
// RMS) and the frame's own position do: a moment the model does not follow (a touch, a glitch of
// the detections' timing) would otherwise move that frame by centimetres.
namespace {

double TypicalModelRms(const Bundled& b) {
  std::vector<double> rms;
  rms.reserve(b.at_frame.size());
  for (const auto& [i, a] : b.at_frame) rms.push_back(a.model_rms());
  return util::NearestRankPercentile(rms, 0.5);
}

// A model's position this far below a ball resting on the ground is past the bounce that ended
// its flight (a frame the segmentation left in it): the ball cannot be there.
constexpr double kBelowGroundM = 0.01;

bool BelowGround(const Eigen::Vector3d& p, const recon::TrajectoryOptions& to) {
  return p.z() < to.ground_z_m + to.ball_radius_m - kBelowGroundM;
}

// A frame's own position outvotes the flight model only where its cameras check each other: two
// views meet at a point whatever one of them is off by along the other's epipolar line.
constexpr int kMinKeptViews = 3;

// The rows a refined flight sets: those of its seen span, and the track's outliers between its
// start and its bounce or hit (a last frame whose view an occluder cut is an outlier after the
// last sample the flight kept).
bool InFlightSpan(const recon::Flight& f, const recon::TrajectoryResult& t, size_t i,
                  double time_s) {
  constexpr double kEps = 1e-9;
  if (time_s >= f.t_first_seen_s - kEps && time_s <= f.t_last_seen_s + kEps) return true;
  return i < t.outlier.size() && t.outlier[i] && time_s >= f.t_start_s - kEps &&
         time_s <= f.t_end_s + kEps;
}

bool ModelFailsAt(const Bundled::AtFrame& a, double typical_px) {
  const double model = a.model_rms();
  return model > kMaxModelRmsRatio * typical_px + kModelRmsSlackPx &&
         model > kMaxModelRmsRatio * a.frame_rms() + kModelRmsSlackPx;
}

}  // namespace

FlightBundle BundleFlights(const std::vector<camera::Camera>& cameras,
                           const std::vector<std::vector<CameraMessage>>& messages,
                           double ball_diameter_m, double ball_mass_kg, double sigma_px,
                           std::vector<recon::BallSample>* track) {
  FlightBundle out;
  const std::vector<recon::BallSample> per_frame = *track;
  const recon::TrajectoryOptions to = FlightOptions(ball_diameter_m, ball_mass_kg);
  out.trajectory = recon::AnalyzeTrajectory(per_frame, to);
  // Half the median frame interval around each flight's seen span.
  std::vector<double> dts;
  for (size_t i = 1; i < per_frame.size(); ++i) {
    dts.push_back(per_frame[i].time_s - per_frame[i - 1].time_s);
  }
  const double margin = 0.5 * util::NearestRankPercentile(dts, 0.5);  // the upper middle; 0 if none
  double ss = 0;
  long long nobs = 0;
  std::vector<char> in_flight(track->size(), 0);  // rows a refined flight set
  for (const recon::Flight& f : out.trajectory->flights) {
    const Bundled b = BundleFlight(cameras, messages, f, to, sigma_px, margin, per_frame);
    // A free flight's model explains the candidates about as well as each frame's own position
    // does (those fit 3 parameters to each frame's 4+ coordinates: RMS about 0.5-0.8 of the
    // model's); a ball carried, dribbled or deflected does not fit one and keeps its frames.
    if (!b.ok || b.at_frames == 0 ||
        b.model_rms_at_frames_px > kMaxModelRmsRatio * b.frames_rms_px + kModelRmsSlackPx ||
        b.near_frames < kMinNearShare * b.span_frames) {
      ++out.kept_flights;
      continue;
    }
    ++out.bundled_flights;
    ss += b.rms_px * b.rms_px * b.observations;
    nobs += b.observations;
    const double typical_px = TypicalModelRms(b);
    for (size_t i = 0; i < track->size(); ++i) {
      recon::BallSample& s = (*track)[i];
      if (in_flight[i] || !InFlightSpan(f, *out.trajectory, i, s.time_s)) continue;
      const auto a = b.at_frame.find(i);
      const Eigen::Vector3d p = b.model.PositionAt(s.time_s);
      if ((a != b.at_frame.end() && s.n_cams >= kMinKeptViews &&
           ModelFailsAt(a->second, typical_px)) ||
          BelowGround(p, to)) {
        ++out.kept_rows;
        continue;
      }
      s.ball_in_world = p;
      s.err_px = b.rms_px;
      in_flight[i] = 1;
      ++out.bundled_rows;
    }
  }
  out.observations = nobs;
  if (nobs > 0) out.rms_px = std::sqrt(ss / nobs);
  out.rests = BundleRests(cameras, messages, to.ball_radius_m, margin, in_flight,
                          RestBundleOptions(), track);
  return out;
}

std::string DetectionsJobResult::Summary() const {
  std::string s = fmt::format("{} detections, {} moments paired by time, {} 3D positions",
                              candidates, frames, positions);
  if (bundled_flights > 0) {
    s += fmt::format("; {} flights refined on the 2D detections ({} rows, {:.2f} px RMS)",
                     bundled_flights, bundled_rows, bundle_rms_px);
    if (kept_rows > 0) s += fmt::format(", {} frames the model does not follow kept", kept_rows);
  }
  if (rests.runs > 0) s += "; " + rests.Summary("the 2D detections");
  for (const auto& p : sync.Problems(camera_names)) s += "\n  " + p;
  if (trajectory) {
    s += '\n';
    s += trajectory->Summary();
  }
  return s;
}

DetectionsJobResult RunDetectionsJob(const DetectionsJobOptions& o) {
  o.Check();
  FV_REQUIRE(o.truth.empty() || std::filesystem::exists(o.truth), "truth file '{}' does not exist",
             o.truth);
  const int n = static_cast<int>(o.cameras.size());
  std::vector<camera::Camera> cameras;
  cameras.reserve(n);
  for (int c = 0; c < n; ++c) cameras.push_back(ReadRigCamera(o.cameras[c]));
  if (!o.triangulation.single_camera_ground) CheckRigSpread(cameras, o.cameras);
  DetectionsJobResult res;
  for (const camera::Camera& cam : cameras) res.camera_names.push_back(cam.name);
  SyncOptions so;
  so.mode = SyncMode::kTimestamp;
  so.tolerance_s = o.tolerance_s;
  FrameSynchronizer sync(n, so);
  std::vector<std::vector<CameraMessage>> messages(n);
  for (int c = 0; c < n; ++c) {
    messages[c] = ReadDetectionsCsv(o.detections[c], c, o.sigma_px);
    for (const auto& m : messages[c]) {
      res.candidates += static_cast<long long>(m.candidates.size());
      sync.Add(m);
    }
    sync.EndOfStream(c);
  }
  recon::TriangulationOptions topt = o.triangulation;
  topt.ball_radius_m = 0.5 * o.ball_diameter_m;
  // Detections made elsewhere carry scores of no known scale (1 when the file has none).
  if (!o.own_scores) topt.min_two_view_score = 0.0;
  FusionStage fusion(cameras, topt);  // the same fusion as the ball pipeline's
  while (auto f = sync.Next()) {
    ++res.frames;
    const BallFrame b = fusion.Fuse(*f);
    if (!b.result.ok()) continue;
    const recon::BallSample s = BallSampleOf(b);
    if (res.per_frame.empty() || s.time_s > res.per_frame.back().time_s) res.per_frame.push_back(s);
  }
  res.sync = sync.report();
  res.sync.gaps_are_drops = false;
  res.track = res.per_frame;
  // Flights, then the bundle.
  if (o.bundle) {
    FlightBundle b =
        BundleFlights(cameras, messages, o.ball_diameter_m, o.ball_mass_kg, o.sigma_px, &res.track);
    res.trajectory = std::move(b.trajectory);
    res.bundled_flights = b.bundled_flights;
    res.bundled_rows = b.bundled_rows;
    res.kept_rows = b.kept_rows;
    res.bundle_rms_px = b.rms_px;
    res.rests = b.rests;
  } else if (!o.flights.empty()) {
    res.trajectory =
        recon::AnalyzeTrajectory(res.per_frame, FlightOptions(o.ball_diameter_m, o.ball_mass_kg));
  }
  res.positions = static_cast<long long>(res.track.size());
  util::AtomicOutput out_file(o.out);
  util::CsvWriter csv(out_file.temp_path(), recon::BallCsvColumns(), 6);
  for (const auto& s : res.track) {
    csv << s.frame << s.time_s << s.ball_in_world.x() << s.ball_in_world.y() << s.ball_in_world.z()
        << s.n_cams << s.err_px;
    csv.EndRow();
  }
  out_file.CloseAndCommit(csv);
  if (!o.truth.empty()) res.eval = recon::EvaluateBallFiles(o.truth, o.out, o.eval);
  if (!o.flights.empty()) {
    util::WriteTextFile(o.flights, recon::FlightsToJson(*res.trajectory).dump(2) + "\n",
                        "--flights");
  }
  return res;
}

}  // namespace fv::pipeline
