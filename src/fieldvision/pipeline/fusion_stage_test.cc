// The fusion stage's predictor (a prior only from a track, two recent positions a plausible step
// apart, never from independent placements) and its hover filter (an airborne point that stands
// still is not the ball).
#include "fieldvision/pipeline/fusion_stage.h"

#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "fieldvision/util/error.h"

namespace fv::pipeline {
namespace {

using Eigen::Vector3d;

TEST(BallPredictor, PredictsAlongATrackOnly) {
  BallPredictor p(/*max_gap=*/5, /*max_step_m=*/1.5);
  EXPECT_FALSE(p.Predict(0).has_value());
  p.Add(10, Vector3d(0, 0, 0.11));
  EXPECT_FALSE(p.Predict(11).has_value());  // one position is no track
  p.Add(12, Vector3d(1, 0.5, 0.11));        // 0.56 m a frame
  const auto at14 = p.Predict(14);
  ASSERT_TRUE(at14.has_value());
  EXPECT_TRUE(at14->isApprox(Vector3d(2, 1, 0.11)));
  EXPECT_FALSE(p.Predict(18).has_value());  // the newest is more than 5 frames old
  EXPECT_FALSE(p.Predict(11).has_value());  // before the newest
  p.Add(13, Vector3d(6, -3, 0.11));         // a jump of 6 m in a frame: another object
  EXPECT_FALSE(p.Predict(14).has_value());
  p.Add(20, Vector3d(6.5, -3, 0.11));  // 7 frames after the last: too far apart
  EXPECT_FALSE(p.Predict(21).has_value());
  p.Add(21, Vector3d(6.6, -3, 0.11));
  ASSERT_TRUE(p.Predict(22).has_value());
  EXPECT_TRUE(p.Predict(22)->isApprox(Vector3d(6.7, -3, 0.11)));
}

TEST(HoverFilter, AStillAirbornePointIsFlaggedAfterTheSpan) {
  HoverFilter filter;  // 25 cm, 0.3 s, 3 frames
  const Vector3d sign(3.0, -6.8, 0.62);
  int first_flagged = -1;
  for (int f = 0; f < 40; ++f) {
    // Jitter of a few cm, as a far object's triangulation has.
    const Vector3d p = sign + 0.02 * Vector3d(std::sin(f), std::cos(3 * f), std::sin(7 * f));
    if (filter.RecordAndTest(f / 60.0, p, 0.01) && first_flagged < 0) first_flagged = f;
  }
  EXPECT_EQ(first_flagged, 18);  // 0.3 s after the first sighting at 60 fps
}

TEST(HoverFilter, ASecondPassFlagsAGhostFromItsFirstFrame) {
  // The first pass over a clip remembers the ghost's whole life; the second one, knowing it,
  // flags it from its first sighting, while the flying ball of the same clip stays a ball.
  const Vector3d ghost(1.1, 3.83, 2.45);
  auto ghost_at = [&](int f) -> Vector3d {
    return ghost + Vector3d(0.075 * std::sin(2.1 * f), 0.01 * std::cos(f), 0.01 * std::sin(5 * f));
  };
  auto ball_at = [](int f) -> Vector3d {
    const double t = f / 60.0;
    return Vector3d(-3 + 10.4 * t, 0.5, 0.11 + 6.0 * t - 0.5 * 9.81 * t * t);
  };
  HoverFilter first;
  for (int f = 0; f < 40; ++f) {
    first.RecordAndTest(f / 60.0, ghost_at(f), 0.01);
    first.RecordAndTest(f / 60.0, ball_at(f), 0.005);
  }
  HoverFilter second;
  second.RememberAfter(first, -1.0);
  for (int f = 0; f < 40; ++f) {
    EXPECT_TRUE(second.RecordAndTest(f / 60.0, ghost_at(f), 0.01)) << "frame " << f;
    EXPECT_FALSE(second.RecordAndTest(f / 60.0, ball_at(f), 0.005)) << "frame " << f;
  }
  // Without the first pass the ghost passes for its first 0.3 s.
  HoverFilter alone;
  EXPECT_FALSE(alone.RecordAndTest(0.0, ghost_at(0), 0.01));
}

TEST(HoverFilter, AFlyingBallIsNeverFlagged) {
  HoverFilter filter;
  for (int f = 0; f < 70; ++f) {  // kicked at 12 m/s, 30 deg up: 1.15 s of flight
    const double t = f / 60.0;
    const Vector3d p(-3 + 10.4 * t, 0.5, 0.11 + 6.0 * t - 0.5 * 9.81 * t * t);
    if (p.z() < 0.11) break;
    EXPECT_FALSE(filter.RecordAndTest(t, p, 0.005)) << "frame " << f;
  }
}

TEST(HoverFilter, AGhostThatJittersAlongTheStandsIsFlagged) {
  // Two cameras' seat candidates meeting above the field: its x wanders by 15 cm from frame to
  // frame (the blobs' shapes), its height by 1 cm.
  HoverFilter filter;
  const Vector3d ghost(1.1, 3.83, 2.45);
  int first_flagged = -1;
  for (int f = 0; f < 40; ++f) {
    const Vector3d p =
        ghost + Vector3d(0.075 * std::sin(2.1 * f), 0.01 * std::cos(f), 0.01 * std::sin(5 * f));
    if (filter.RecordAndTest(f / 60.0, p, 0.01) && first_flagged < 0) first_flagged = f;
  }
  EXPECT_GE(first_flagged, 18);
  EXPECT_LE(first_flagged, 24);
}

TEST(HoverFilter, ASlowBallNearItsApexOrPassingAPointTwiceIsNeverFlagged) {
  // Thrown up at 3 m/s and drifting at 0.2 m/s: 0.45 s within 25 cm of its apex; then juggled
  // again from the same place (the same heights twice).
  HoverFilter filter;
  for (int f = 0; f < 120; ++f) {
    const double t = f / 60.0;
    const double in_throw = std::fmod(t, 0.6);
    const Vector3d p(2 + 0.2 * in_throw, 1,
                     0.5 + 3.0 * in_throw - 0.5 * 9.81 * in_throw * in_throw);
    EXPECT_FALSE(filter.RecordAndTest(t, p, 0.01)) << "frame " << f;
  }
}

TEST(HoverFilter, OnlyPointsAboveARestingBallAreAirborne) {
  HoverFilter filter(HoverFilterOptions(), /*ball_radius_m=*/0.11);
  EXPECT_FALSE(filter.Airborne(Vector3d(1, 2, 0.11), 0.002));  // resting
  EXPECT_FALSE(filter.Airborne(Vector3d(1, 2, 0.15), 0.002));  // within 5 cm
  EXPECT_TRUE(filter.Airborne(Vector3d(1, 2, 0.30), 0.002));
  EXPECT_FALSE(filter.Airborne(Vector3d(1, 2, 0.30), 0.1));  // too uncertain to tell
  recon::TriangulationResult on_ground;
  on_ground.status = recon::TriangulationStatus::kOk;
  on_ground.on_ground = true;
  on_ground.point_world = Vector3d(1, 2, 0.5);
  EXPECT_FALSE(filter.Airborne(on_ground));
}

TEST(HoverFilter, BadOptionsAreRefused) {
  HoverFilterOptions o;
  o.min_count = 1;
  EXPECT_THROW(HoverFilter{o}, fv::Error);
  o = HoverFilterOptions();
  o.radius_m = std::nan("");
  EXPECT_THROW(HoverFilter{o}, fv::Error);
}

// Three cameras 10 m from the field centre, 5 m high, looking at it.
std::vector<camera::Camera> RingCameras() {
  std::vector<camera::Camera> cams;
  for (int i = 0; i < 3; ++i) {
    const double a = 2 * M_PI * i / 3;
    camera::Camera c = camera::Camera::FromFov(1280, 960, 70);
    c.name = "cam" + std::to_string(i + 1);
    c.cam_from_world = geometry::Rigid3d::LookAt(
        Eigen::Vector3d(10 * std::cos(a), 10 * std::sin(a), 5), {0, 0, 0});
    c.has_pose = true;
    cams.push_back(c);
  }
  return cams;
}

recon::BallObservation SeenAt(const camera::Camera& cam, const Vector3d& p, double score) {
  recon::BallObservation o;
  o.centre_px = *recon::PredictBallCentre(cam, p, 0.11);
  o.radius_px = 0.11 * cam.fx / (cam.cam_from_world * p).z();
  o.sigma_px = 0.3;
  o.score = score;
  return o;
}

// A yellow sign 0.6 m above the ground that cameras 1 and 2 both take for a ball, in every frame,
// and the ball at rest in view of all three cameras in the frames where `ball_seen`: fused frame
// by frame (60 fps), how many positions lie on the ball and how many on the sign.
struct SignAndBall {
  int ball_frames = 0, sign_frames = 0;
};
SignAndBall FuseSignAndBall(FusionStage& fusion, const std::vector<camera::Camera>& cams,
                            int frames, const std::function<bool(int)>& ball_seen) {
  const Vector3d ball(-1.0, 0.5, 0.11), sign(2.0, 1.5, 0.6);
  SignAndBall n;
  for (int f = 0; f < frames; ++f) {
    SyncedFrame group;
    group.frame = f;
    group.time_s = f / 60.0;
    group.cameras.resize(cams.size());
    for (int c = 0; c < 3; ++c) {
      CameraMessage m;
      m.camera = c;
      m.frame = f;
      m.time_s = group.time_s;
      if (ball_seen(f)) m.candidates.push_back(SeenAt(cams[c], ball, 0.5));
      if (c < 2) m.candidates.push_back(SeenAt(cams[c], sign, 0.6));
      group.cameras[c] = m;
    }
    const BallFrame out = fusion.Fuse(group);
    if (!out.result.ok()) continue;
    if ((out.result.point_world - ball).norm() < 0.05) ++n.ball_frames;
    if ((out.result.point_world - sign).norm() < 0.05) ++n.sign_frames;
  }
  return n;
}

// The ball rests in view of all three cameras, then is hidden (picked up). The sign, seen all
// along as a consistent pair that was not chosen, must not take the ball's place.
TEST(FusionStage, AStillSignDoesNotReplaceALostBall) {
  const std::vector<camera::Camera> cams = RingCameras();
  FusionStage fusion(cams, recon::TriangulationOptions());
  const SignAndBall n = FuseSignAndBall(fusion, cams, 60, [](int f) { return f < 30; });
  EXPECT_EQ(n.ball_frames, 30);
  EXPECT_EQ(n.sign_frames, 0);
  // For 12 frames (BallPredictor's max_gap) the resting ball's track gates the sign out; then
  // it is chosen and dropped.
  EXPECT_EQ(fusion.stats().hovering_dropped, 30 - 12);
}

// The sign is all cameras 1 and 2 see for a moment (the ball is out of view), so the fusion
// follows it; then the ball comes to rest in view of all three cameras. A track that stands
// still in the air is no ball's and gives no prior: the ball is taken from its first frame (gated
// by the sign's track, it was kept out until the hover filter had seen the sign for 0.3 s).
TEST(FusionStage, AStillSignFollowedForAMomentDoesNotKeepTheBallOut) {
  const std::vector<camera::Camera> cams = RingCameras();
  FusionStage fusion(cams, recon::TriangulationOptions());
  const SignAndBall n = FuseSignAndBall(fusion, cams, 30, [](int f) { return f >= 5; });
  EXPECT_EQ(n.ball_frames, 25);
  EXPECT_EQ(n.sign_frames, 5);
}

}  // namespace
}  // namespace fv::pipeline
