#include "fieldvision/pipeline/fusion_stage.h"

#include <algorithm>
#include <cmath>

#include "fieldvision/pipeline/camera_stage.h"
#include "fieldvision/util/error.h"

namespace fv::pipeline {
namespace {

// A track that moves at least this much a frame (3 m/s at 60 fps) is exempt from the hover
// filter; a hovering point is fused again without its candidates at most this many times.
constexpr double kMovingTrackStepM = 0.05;
constexpr int kMaxHoverRetries = 2;

}  // namespace

void BallPredictor::Add(long long frame, const Eigen::Vector3d& point_world) {
  frame_[1] = frame_[0];
  point_[1] = point_[0];
  frame_[0] = frame;
  point_[0] = point_world;
  count_ = std::min(count_ + 1, 2);
}

std::optional<Eigen::Vector3d> BallPredictor::Predict(long long frame) const {
  if (count_ < 2 || frame - frame_[0] > max_gap_ || frame < frame_[0]) return std::nullopt;
  if (frame_[0] - frame_[1] > max_gap_ || frame_[0] <= frame_[1]) return std::nullopt;
  const Eigen::Vector3d v = (point_[0] - point_[1]) / double(frame_[0] - frame_[1]);
  if (v.norm() > max_step_m_) return std::nullopt;
  return point_[0] + v * double(frame - frame_[0]);
}

std::optional<double> BallPredictor::StepPerFrame(long long frame) const {
  if (!Predict(frame)) return std::nullopt;
  return (point_[0] - point_[1]).norm() / double(frame_[0] - frame_[1]);
}

void HoverFilterOptions::Check() const {
  FV_REQUIRE(radius_m > 0 && std::isfinite(radius_m), "HoverFilterOptions.radius_m must be > 0");
  FV_REQUIRE(min_span_s >= 0 && std::isfinite(min_span_s),
             "HoverFilterOptions.min_span_s must be >= 0");
  FV_REQUIRE(min_count >= 2, "HoverFilterOptions.min_count must be >= 2 (got {})", min_count);
  FV_REQUIRE(airborne_m >= 0 && std::isfinite(airborne_m),
             "HoverFilterOptions.airborne_m must be >= 0");
  FV_REQUIRE(memory_s > min_span_s && std::isfinite(memory_s),
             "HoverFilterOptions.memory_s must exceed min_span_s");
}

HoverFilter::HoverFilter(const HoverFilterOptions& options, double ball_radius_m)
    : options_(options), ball_radius_m_(ball_radius_m) {
  options_.Check();
}

bool HoverFilter::Airborne(const recon::TriangulationResult& result) const {
  if (!result.ok() || result.on_ground) return false;
  return Airborne(result.point_world, std::sqrt(std::max(result.covariance(2, 2), 0.0)));
}

bool HoverFilter::Airborne(const Eigen::Vector3d& point_world, double sigma_z_m) const {
  return point_world.z() - ball_radius_m_ > options_.airborne_m + 3 * sigma_z_m;
}

void HoverFilter::Record(double time_s, const Eigen::Vector3d& point_world, double sigma_m) {
  while (!seen_.empty() && seen_.front().time_s < time_s - options_.memory_s) seen_.pop_front();
  seen_.push_back({time_s, point_world, sigma_m});
  constexpr size_t kMaxRemembered = 8192;
  if (seen_.size() > kMaxRemembered) seen_.pop_front();
}

double HoverFilter::RememberAfter(const HoverFilter& other, double after_time_s) {
  double latest = after_time_s;
  for (const Seen& s : other.seen_) {
    if (s.time_s > after_time_s) {
      seen_.push_back(s);
      latest = std::max(latest, s.time_s);
    }
  }
  return latest;
}

bool HoverFilter::RecordAndTest(double time_s, const Eigen::Vector3d& point_world, double sigma_m) {
  std::vector<double> times;  // other frames that saw this point
  double z_min = point_world.z(), z_max = point_world.z();
  for (const Seen& s : seen_) {
    const double tolerance_m = std::max(options_.radius_m, 3 * std::hypot(sigma_m, s.sigma_m));
    if (s.time_s != time_s && (s.point_world - point_world).norm() <= tolerance_m) {
      times.push_back(s.time_s);
      z_min = std::min(z_min, s.point_world.z());
      z_max = std::max(z_max, s.point_world.z());
    }
  }
  Record(time_s, point_world, sigma_m);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  const int count = 1 + static_cast<int>(times.size());
  if (count < options_.min_count || times.empty() ||
      std::max(times.back(), time_s) - std::min(times.front(), time_s) < options_.min_span_s) {
    return false;
  }
  // A free ball's heights span at least g T^2 / 8 over any T seconds (T/2 each side of an apex).
  constexpr double kGravity = 9.81;
  const double t = options_.min_span_s;
  return z_max - z_min < 0.5 * kGravity * t * t / 8;
}

recon::BallSample BallSampleOf(const BallFrame& f) {
  recon::BallSample s;
  s.frame = f.frame;
  s.time_s = f.time_s;
  s.ball_in_world = f.result.point_world;
  s.n_cams = f.result.num_views();
  s.err_px = f.result.rms_px;
  return s;
}

BallFrame FuseFrame(const std::vector<camera::Camera>& cameras, const SyncedFrame& frame,
                    const recon::TriangulationOptions& options, const Eigen::Vector3d* prior) {
  BallFrame out;
  out.frame = frame.frame;
  out.time_s = frame.time_s;
  std::vector<std::vector<recon::BallObservation>> candidates(cameras.size());
  for (size_t c = 0; c < cameras.size() && c < frame.cameras.size(); ++c) {
    if (!frame.cameras[c]) continue;
    ++out.cameras_present;
    candidates[c] = frame.cameras[c]->candidates;
    if (HasAccepted(candidates[c])) ++out.cameras_with_blobs;
  }
  out.result = recon::TriangulateRobust(cameras, candidates, options, prior);
  return out;
}

FusionStage::FusionStage(std::vector<camera::Camera> cameras,
                         const recon::TriangulationOptions& options)
    : cameras_(std::move(cameras)),
      options_(options),
      hover_(HoverFilterOptions(), options.ball_radius_m) {
  FV_REQUIRE(!cameras_.empty(), "fusion stage: no cameras");
  options.Check();
  stats_.used_per_camera.assign(cameras_.size(), 0);
  stats_.candidates_per_camera.assign(cameras_.size(), 0);
}

BallFrame FusionStage::Fuse(const SyncedFrame& group) {
  for (size_t c = 0; c < cameras_.size() && c < group.cameras.size(); ++c) {
    if (!group.cameras[c]) continue;
    for (const recon::BallObservation& o : group.cameras[c]->candidates) {
      stats_.candidates_per_camera[c] += !o.weak;
    }
  }
  auto prior = predictor_.Predict(group.frame);
  const auto step_m = predictor_.StepPerFrame(group.frame);
  const bool moving_track = step_m && *step_m >= kMovingTrackStepM;
  // A ball cannot hover: a track that stands still in the air is a ball-coloured thing's, and
  // gating by it would keep the ball elsewhere out (even seen by every camera) until the hover
  // filter has seen it long enough.
  if (prior && !moving_track && hover_.Airborne(*prior, 0.0)) prior.reset();
  BallFrame f = FuseFrame(cameras_, group, options_, prior ? &*prior : nullptr);
  // An airborne point that stands still is something ball-coloured, not the ball (HoverFilter):
  // fuse again without its candidates, unless a moving track (a ball passing a point twice,
  // up and down) led there.
  for (const auto& alt : f.result.alternatives) {
    // An alternative's height is known to about its 3D size.
    if (hover_.Airborne(alt.point_world, alt.sigma_m)) {
      hover_.Record(group.time_s, alt.point_world, alt.sigma_m);
    }
  }
  SyncedFrame without;
  for (int attempt = 0; attempt < kMaxHoverRetries && hover_.Airborne(f.result); ++attempt) {
    const double sigma_m = std::sqrt(std::max(f.result.covariance.trace(), 0.0));
    if (!hover_.RecordAndTest(group.time_s, f.result.point_world, sigma_m) || moving_track) {
      break;
    }
    ++stats_.hovering_dropped;
    if (attempt == 0) without = group;
    for (const recon::ViewResidual& v : f.result.views) {
      auto& message = without.cameras[v.camera];
      if (!message || v.candidate < 0 ||
          v.candidate >= static_cast<int>(message->candidates.size())) {
        continue;
      }
      message->candidates.erase(message->candidates.begin() + v.candidate);
    }
    f = FuseFrame(cameras_, without, options_, prior ? &*prior : nullptr);
  }
  if (f.result.ok() && !f.result.on_ground) predictor_.Add(f.frame, f.result.point_world);
  ++stats_.frames;
  if (f.result.ok()) {
    ++stats_.frames_with_position;
    if (f.result.on_ground) ++stats_.ground_positions;
    if (f.result.weak_views > 0) ++stats_.weak_positions;
    stats_.sum_err_px += f.result.rms_px;
    for (const auto& v : f.result.views) ++stats_.used_per_camera[v.camera];
  } else if (f.cameras_with_blobs < 2) {
    ++stats_.frames_few_blobs;
  } else {
    ++stats_.frames_inconsistent;
  }
  return f;
}

}  // namespace fv::pipeline
