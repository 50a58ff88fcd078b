#include "fieldvision/pipeline/fusion_stage.h"

#include <algorithm>

#include "fieldvision/pipeline/camera_stage.h"
#include "fieldvision/util/error.h"

namespace fv::pipeline {

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
    : cameras_(std::move(cameras)), options_(options) {
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
  const auto prior = predictor_.Predict(group.frame);
  BallFrame f = FuseFrame(cameras_, group, options_, prior ? &*prior : nullptr);
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
