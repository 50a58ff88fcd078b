#include "fieldvision/pipeline/ball_hints.h"

#include <algorithm>
#include <cmath>

#include "fieldvision/util/error.h"

namespace fv::pipeline {
namespace {

constexpr double kGravityMps2 = 9.81;

// Where a hinted ball is `age_s` after its time.
Eigen::Vector3d BallAfter(const BallHint& h, double age_s) {
  Eigen::Vector3d p = h.ball_in_world + age_s * h.velocity_mps;
  if (h.airborne) p.z() -= 0.5 * kGravityMps2 * age_s * age_s;
  return p;
}

}  // namespace

void BallHintOptions::Check() const {
  FV_REQUIRE(lag_messages >= 1, "BallHintOptions.lag_messages must be >= 1 (got {})", lag_messages);
  CheckPositive(max_age_s, "BallHintOptions.max_age_s");
  CheckPositive(max_gap_s, "BallHintOptions.max_gap_s");
  CheckPositive(max_speed_mps, "BallHintOptions.max_speed_mps");
  CheckNonNegative(airborne_m, "BallHintOptions.airborne_m");
}

std::optional<ExpectedBall> ExpectBall(const BallHint& hint, const camera::Camera& camera,
                                       double time_s, double frame_dt_s,
                                       const BallHintOptions& options) {
  const double age_s = time_s - hint.time_s;
  if (!(age_s >= 0.0 && age_s <= options.max_age_s) || !camera.has_pose) return std::nullopt;
  const Eigen::Vector3d at = BallAfter(hint, age_s);
  const std::optional<Eigen::Vector2d> uv = camera.Project(at);
  if (!uv || !uv->allFinite() || !camera.InImage(*uv)) return std::nullopt;
  const Eigen::Vector3d in_cam = camera.cam_from_world * at;
  if (in_cam.z() <= hint.radius_m) return std::nullopt;
  ExpectedBall e;
  e.centre_px = *uv;
  e.radius_px = hint.radius_m / camera.PixelFootprintM(at);
  const std::optional<Eigen::Vector2d> before =
      camera.Project(BallAfter(hint, age_s - std::max(frame_dt_s, 0.0)));
  if (before && before->allFinite()) e.step_px = *uv - *before;
  if (!std::isfinite(e.radius_px) || !e.step_px.allFinite()) return std::nullopt;
  return e;
}

BallHintBoard::BallHintBoard(int cameras, const BallHintOptions& options, bool wait)
    : options_(options), wait_(wait), popped_(cameras, 0), at_pop_(cameras) {
  options_.Check();
  FV_REQUIRE(cameras >= 1, "ball hints: no cameras");
}

void BallHintBoard::Publish(double time_s, const Eigen::Vector3d& ball_in_world, double radius_m) {
  if (!std::isfinite(time_s) || !ball_in_world.allFinite()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  BallHint h;
  h.time_s = time_s;
  h.ball_in_world = ball_in_world;
  h.radius_m = radius_m;
  const double flying_z = radius_m + options_.airborne_m;
  if (state_) {
    const double dt = time_s - state_->time_s;
    Eigen::Vector3d v = (ball_in_world - state_->ball_in_world) / dt;
    if (dt > 0 && dt <= options_.max_gap_s && v.norm() <= options_.max_speed_mps) {
      // In flight the step's mean velocity is the one half a step back.
      h.airborne = ball_in_world.z() > flying_z && state_->ball_in_world.z() > flying_z;
      if (h.airborne) v.z() -= 0.5 * kGravityMps2 * dt;
      h.velocity_mps = v;
    }
  }
  state_ = h;
}

void BallHintBoard::Popped(int camera) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++popped_.at(camera);
    auto& q = at_pop_[camera];
    q.push_back(state_);
    while (q.size() > static_cast<size_t>(options_.lag_messages) + 1) q.pop_front();
  }
  changed_.notify_all();
}

std::optional<BallHint> BallHintBoard::Get(int camera, long long index) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!wait_) return state_;
  const long long want = index - options_.lag_messages;  // the message whose pop counts
  if (want < 0) return std::nullopt;
  changed_.wait(lock, [&] { return closed_ || popped_.at(camera) > want; });
  if (closed_) return std::nullopt;
  // popped_ - 1 is the back of at_pop_; a stage is never more than lag messages ahead.
  const auto& q = at_pop_[camera];
  const long long back = popped_[camera] - 1;
  const long long from_back = back - want;
  if (from_back < 0 || from_back >= static_cast<long long>(q.size())) return std::nullopt;
  return q[q.size() - 1 - static_cast<size_t>(from_back)];
}

void BallHintBoard::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

}  // namespace fv::pipeline
