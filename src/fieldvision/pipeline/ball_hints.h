// What the fusion stage knows of the ball, handed back to the camera stages: the last fused 3D
// position and its velocity, so that a camera whose own image track has settled on a
// ball-coloured thing (a seat, a board: the best-scored candidate is not always the ball) looks
// where the cameras together saw the ball, and fits it there (camera_stage.h). Offline the
// board is deterministic: a camera stage reads, for its message k, the state the fusion had when
// it took that camera's message k - lag off the queue (it waits for that), so results do not
// depend on thread timing; it cannot deadlock, since a stage that waits has at least `lag`
// messages queued for the fusion. Live (no waiting), a stage reads the newest state.
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "fieldvision/camera/camera.h"

namespace fv::pipeline {

// The ball's fused state (world z up).
struct BallHint {
  double time_s = 0.0;  // when it was seen there
  Eigen::Vector3d ball_in_world = Eigen::Vector3d::Zero();
  // At time_s; zero from a single position. In flight (airborne) gravity acts on it.
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  double radius_m = 0.11;
  bool airborne = false;  // both positions it came from were above a resting ball
  // The positions its line was fitted to; 1: the newest alone, without velocity (a single one, a
  // jump, positions that disagree).
  int positions = 1;
};

// Where a camera expects the ball at a time: its image centre and radius, and its image motion
// per `frame_dt_s`.
struct ExpectedBall {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double radius_px = 0.0;
  Eigen::Vector2d step_px = Eigen::Vector2d::Zero();
};

struct BallHintOptions {
  int lag_messages = 2;         // offline: message k reads the state at the pop of k - lag (>= 1)
  double max_age_s = 0.25;      // a state older than this (at the frame's time) is no hint
  double max_gap_s = 0.1;       // two positions farther apart in time give no velocity
  double max_speed_mps = 60.0;  // a faster step between two positions is a jump, no velocity
  double airborne_m = 0.05;     // above a resting ball's centre by this much: in flight
  // The state is a line (a parabola in flight) fitted to the positions of the last fit_span_s
  // (each within max_gap_s of the next), dropping the worst one while it is farther than
  // outlier_m from the fit (a position on another object) and more than two remain (when two are
  // left so, the newest alone); when the two newest are both dropped the ball was kicked, and the
  // line is theirs.
  double fit_span_s = 0.1;
  double outlier_m = 0.15;
  void Check() const;  // throws fv::Error naming the bad field
};

// The ball's expected image position in `camera` at `time_s` (from the hint: constant velocity,
// plus gravity in flight), nullopt when the hint is too old, the ball is behind the camera or
// outside the image.
std::optional<ExpectedBall> ExpectBall(const BallHint& hint, const camera::Camera& camera,
                                       double time_s, double frame_dt_s,
                                       const BallHintOptions& options);

// The state from recent fused positions (time_s, position; oldest first, at least one) as
// BallHintOptions describes; the newest position alone has no velocity.
BallHint FitHint(const std::deque<std::pair<double, Eigen::Vector3d>>& recent, double radius_m,
                 const BallHintOptions& options);

class BallHintBoard {
 public:
  // `wait`: offline (deterministic; see above); false: live.
  BallHintBoard(int cameras, const BallHintOptions& options, bool wait);
  const BallHintOptions& options() const { return options_; }
  // Fusion thread: a fused 3D position (not a ground one) at `time_s`.
  void Publish(double time_s, const Eigen::Vector3d& ball_in_world, double radius_m);
  // Fusion thread: it took `camera`'s next message off its queue.
  void Popped(int camera);
  // Camera thread: the state for that camera's message `index` (0-based); nullopt when none.
  // Offline it waits until the fusion popped message index - lag, or the board is closed.
  std::optional<BallHint> Get(int camera, long long index);
  // Releases every waiting camera (the fusion ended or failed); Get then returns nullopt.
  void Close();
  // Whether the fusion tells of frames without a position too (a fusion node's lost hints): then
  // a board without a recent position means the cameras together have none (CameraStage's
  // unconfirmed scans).
  void MarkTellsLoss() { tells_loss_ = true; }
  bool TellsLoss() const { return tells_loss_; }

 private:
  BallHintOptions options_;
  bool wait_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool closed_ = false;
  std::atomic<bool> tells_loss_{false};
  std::optional<BallHint> state_;
  std::deque<std::pair<double, Eigen::Vector3d>> recent_;  // (time_s, position), oldest first
  std::vector<long long> popped_;                          // messages popped per camera
  // Per camera, the state at each of its last pops (back: the latest, popped_[c] - 1).
  std::vector<std::deque<std::optional<BallHint>>> at_pop_;
};

}  // namespace fv::pipeline
