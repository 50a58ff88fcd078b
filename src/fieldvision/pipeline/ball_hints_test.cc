// The fusion's hints to the camera stages: offline a stage's message k reads the state the
// fusion had when it popped message k - lag (waiting for it), whatever the threads' timing;
// Close releases a waiting stage; the expected image position follows the ball's velocity.
#include "fieldvision/pipeline/ball_hints.h"

#include <chrono>
#include <future>
#include <thread>

#include <gtest/gtest.h>

#include "fieldvision/camera/sphere_image.h"
#include "fieldvision/util/error.h"

namespace fv::pipeline {
namespace {

using Eigen::Vector3d;

TEST(BallHintBoard, AMessageReadsTheStateAtThePopOfTheMessageLagBefore) {
  BallHintOptions o;
  o.lag_messages = 2;
  BallHintBoard board(2, o, /*wait=*/true);
  EXPECT_FALSE(board.Get(0, 0));  // nothing to wait for, nothing known
  EXPECT_FALSE(board.Get(0, 1));
  board.Popped(0);  // message 0 popped before any position: message 2 reads none
  board.Publish(0.0, Vector3d(1, 0, 0), 0.11);
  board.Popped(0);  // message 1: the position at t = 0
  board.Publish(0.1, Vector3d(2, 0, 0), 0.11);
  board.Popped(1);
  EXPECT_FALSE(board.Get(0, 2));
  const std::optional<BallHint> h3 = board.Get(0, 3);
  ASSERT_TRUE(h3);
  EXPECT_EQ(h3->ball_in_world, Vector3d(1, 0, 0));
  EXPECT_EQ(h3->velocity_mps, Vector3d::Zero());  // one position: no velocity
  // Camera 1's message 2 reads the state at its pop 0: both positions, the velocity 10 m/s.
  const std::optional<BallHint> h = board.Get(1, 2);
  ASSERT_TRUE(h);
  EXPECT_EQ(h->ball_in_world, Vector3d(2, 0, 0));
  EXPECT_NEAR(h->velocity_mps.x(), 10.0, 1e-9);
  EXPECT_NEAR(h->time_s, 0.1, 1e-12);
  // Later publications do not change what an earlier pop saw.
  board.Publish(0.2, Vector3d(3, 0, 0), 0.11);
  EXPECT_EQ(board.Get(0, 3)->ball_in_world, Vector3d(1, 0, 0));
}

TEST(BallHintBoard, AStageWaitsForThePopAndCloseReleasesIt) {
  BallHintBoard board(1, BallHintOptions{}, /*wait=*/true);
  board.Publish(0.0, Vector3d(1, 2, 3), 0.11);
  auto waiting = std::async(std::launch::async, [&] { return board.Get(0, 2); });
  EXPECT_EQ(waiting.wait_for(std::chrono::milliseconds(50)), std::future_status::timeout);
  board.Popped(0);
  ASSERT_EQ(waiting.wait_for(std::chrono::seconds(10)), std::future_status::ready);
  const std::optional<BallHint> h = waiting.get();
  ASSERT_TRUE(h);
  EXPECT_EQ(h->ball_in_world, Vector3d(1, 2, 3));
  auto released = std::async(std::launch::async, [&] { return board.Get(0, 5); });
  EXPECT_EQ(released.wait_for(std::chrono::milliseconds(50)), std::future_status::timeout);
  board.Close();
  ASSERT_EQ(released.wait_for(std::chrono::seconds(10)), std::future_status::ready);
  EXPECT_FALSE(released.get());
  // Live: no waiting, the newest state.
  BallHintBoard live(1, BallHintOptions{}, /*wait=*/false);
  EXPECT_FALSE(live.Get(0, 7));
  live.Publish(0.5, Vector3d(4, 5, 6), 0.11);
  EXPECT_EQ(live.Get(0, 7)->ball_in_world, Vector3d(4, 5, 6));
}

TEST(BallHintBoard, AJumpOrAGapGivesNoVelocity) {
  BallHintBoard board(1, BallHintOptions{}, /*wait=*/false);
  board.Publish(0.0, Vector3d(0, 0, 0), 0.11);
  board.Publish(1.0 / 60, Vector3d(5, 0, 0), 0.11);  // 300 m/s: another object
  EXPECT_EQ(board.Get(0, 0)->velocity_mps, Vector3d::Zero());
  board.Publish(1.0, Vector3d(5.1, 0, 0), 0.11);  // a second later
  EXPECT_EQ(board.Get(0, 0)->velocity_mps, Vector3d::Zero());
  EXPECT_THROW(BallHintBoard(0, BallHintOptions{}, true), Error);
  BallHintOptions bad;
  bad.lag_messages = 0;
  EXPECT_THROW(bad.Check(), Error);
}

TEST(BallHintBoard, ThreePositionsOneOffTheLineGiveTheNewestAloneAndALineCountsItsPositions) {
  // Three positions 1 m apart at 60 fps, the middle one off the others' line: which one is off is
  // a guess (a position on another object, or a ball seen at three places), so no velocity.
  BallHintBoard board(1, BallHintOptions{}, /*wait=*/false);
  board.Publish(0.0, Vector3d(0, 0, 0.11), 0.11);
  board.Publish(1.0 / 60, Vector3d(0.5, 1.0, 0.11), 0.11);
  board.Publish(2.0 / 60, Vector3d(0.6, 0, 0.11), 0.11);
  const std::optional<BallHint> h = board.Get(0, 0);
  ASSERT_TRUE(h);
  EXPECT_EQ(h->ball_in_world, Vector3d(0.6, 0, 0.11));
  EXPECT_EQ(h->velocity_mps, Vector3d::Zero());
  EXPECT_EQ(h->positions, 1);
  // Five: the newest far off the older ones' line (on another object), and of the four left two
  // more off: the newest of the two kept, at its own time (not the one judged off).
  BallHintBoard five(1, BallHintOptions{}, /*wait=*/false);
  const std::vector<Vector3d> at = {Vector3d(0, 0, 0.11), Vector3d(0, 3, 0.11),
                                    Vector3d(0, 0, 0.11), Vector3d(0, 1, 0.11),
                                    Vector3d(5, 5, 0.11)};
  for (size_t f = 0; f < at.size(); ++f) five.Publish(f / 60.0, at[f], 0.11);
  const std::optional<BallHint> k = five.Get(0, 0);
  ASSERT_TRUE(k);
  EXPECT_EQ(k->ball_in_world, at[3]);
  EXPECT_NEAR(k->time_s, 3 / 60.0, 1e-12);
  EXPECT_EQ(k->velocity_mps, Vector3d::Zero());
  EXPECT_EQ(k->positions, 1);
  // Four on a line: the line through them.
  BallHintBoard line(1, BallHintOptions{}, /*wait=*/false);
  for (int f = 0; f < 4; ++f) line.Publish(f / 60.0, Vector3d(0.1 * f, 0, 0.11), 0.11);
  EXPECT_EQ(line.Get(0, 0)->positions, 4);
  EXPECT_LT((line.Get(0, 0)->velocity_mps - Vector3d(6, 0, 0)).norm(), 1e-9);
}

TEST(BallHintBoard, AFlyingBallFallsAlongItsParabola) {
  // A ball thrown up at 5 m/s from 2 m: positions at 60 fps; the hint at the third predicts the
  // tenth within a millimetre (constant velocity alone: 9 cm off).
  const auto z = [](double t) { return 2.0 + 5.0 * t - 0.5 * 9.81 * t * t; };
  BallHintBoard board(1, BallHintOptions{}, /*wait=*/false);
  for (int f = 0; f < 3; ++f) board.Publish(f / 60.0, Vector3d(0.1 * f, 0, z(f / 60.0)), 0.11);
  const std::optional<BallHint> h = board.Get(0, 0);
  ASSERT_TRUE(h && h->airborne);
  EXPECT_NEAR(h->velocity_mps.z(), 5.0 - 9.81 * 2 / 60.0, 1e-9);
  camera::Camera cam = camera::Camera::FromFov(640, 480, 60.0);
  cam.has_pose = true;
  cam.cam_from_world = geometry::Rigid3d::LookAt(Vector3d(0, -10, 2), {0, 0, 2});
  const std::optional<ExpectedBall> e = ExpectBall(*h, cam, 9 / 60.0, 1 / 60.0, BallHintOptions{});
  ASSERT_TRUE(e);
  const Eigen::Vector2d truth = *cam.Project(Vector3d(0.9, 0, z(9 / 60.0)));
  EXPECT_LT((e->centre_px - truth).norm(), cam.fx * 0.001 / 10.0);
  // A ball rolling on the ground does not fall.
  BallHintBoard ground(1, BallHintOptions{}, /*wait=*/false);
  ground.Publish(0.0, Vector3d(0, 0, 0.11), 0.11);
  ground.Publish(1 / 60.0, Vector3d(0.1, 0, 0.11), 0.11);
  EXPECT_FALSE(ground.Get(0, 0)->airborne);
  EXPECT_EQ(ground.Get(0, 0)->velocity_mps.z(), 0.0);
}

TEST(BallHintBoard, APositionOnAnotherObjectDoesNotBendTheTrack) {
  // A ball rolling at 6 m/s; the fusion's newest position is 0.4 m off (two cameras agreed on
  // something else): the state stays on the track, with its velocity.
  BallHintBoard board(1, BallHintOptions{}, /*wait=*/false);
  for (int f = 0; f < 5; ++f) board.Publish(f / 60.0, Vector3d(0.1 * f, 0, 0.11), 0.11);
  board.Publish(5 / 60.0, Vector3d(0.5, 0.4, 0.11), 0.11);
  const std::optional<BallHint> h = board.Get(0, 0);
  ASSERT_TRUE(h);
  EXPECT_LT((h->ball_in_world - Vector3d(0.5, 0, 0.11)).norm(), 1e-9);
  EXPECT_LT((h->velocity_mps - Vector3d(6, 0, 0)).norm(), 1e-6);
  EXPECT_NEAR(h->time_s, 5 / 60.0, 1e-12);
  // Two positions off the track that agree with each other: the ball was kicked sideways.
  BallHintBoard kicked(1, BallHintOptions{}, /*wait=*/false);
  for (int f = 0; f < 4; ++f) kicked.Publish(f / 60.0, Vector3d(0.1 * f, 0, 0.11), 0.11);
  kicked.Publish(4 / 60.0, Vector3d(0.3, 0.2, 0.11), 0.11);
  kicked.Publish(5 / 60.0, Vector3d(0.3, 0.4, 0.11), 0.11);
  const std::optional<BallHint> k = kicked.Get(0, 0);
  ASSERT_TRUE(k);
  EXPECT_LT((k->ball_in_world - Vector3d(0.3, 0.4, 0.11)).norm(), 1e-9);
  EXPECT_LT((k->velocity_mps - Vector3d(0, 12, 0)).norm(), 1e-6);
}

TEST(ExpectBall, ProjectsTheBallAheadWithItsVelocityAndSize) {
  camera::Camera cam = camera::Camera::FromFov(640, 480, 60.0);
  cam.has_pose = true;  // at the origin, looking along +z
  BallHint h;
  h.time_s = 1.0;
  h.ball_in_world = Vector3d(0, 0, 10);
  h.velocity_mps = Vector3d(6, 0, 0);
  h.radius_m = 0.11;
  BallHintOptions o;
  const std::optional<ExpectedBall> e = ExpectBall(h, cam, 1.1, 0.05, o);
  ASSERT_TRUE(e);
  const Eigen::Vector2d at = *cam.Project(Vector3d(0.6, 0, 10));
  EXPECT_LT((e->centre_px - at).norm(), 1e-6);
  EXPECT_NEAR(e->radius_px, cam.fx * 0.11 / 10.0, 0.05);
  EXPECT_NEAR(e->step_px.x(), cam.fx * 0.3 / 10.0, 1e-6);               // 0.3 m in 0.05 s
  EXPECT_FALSE(ExpectBall(h, cam, 1.0 + o.max_age_s + 0.01, 0.05, o));  // too old
  EXPECT_FALSE(ExpectBall(h, cam, 0.9, 0.05, o));                       // from the future
  h.ball_in_world = Vector3d(0, 0, -10);                                // behind the camera
  h.velocity_mps.setZero();
  EXPECT_FALSE(ExpectBall(h, cam, 1.0, 0.05, o));
  h.ball_in_world = Vector3d(50, 0, 10);  // outside the image
  EXPECT_FALSE(ExpectBall(h, cam, 1.0, 0.05, o));
}

// Through a barrel lens the ball near the border is smaller than without it: the hint's radius is
// the one the detector will see there.
TEST(ExpectBall, TheRadiusIncludesTheLens) {
  camera::Camera cam = camera::Camera::FromFov(1000, 800, 90.0);
  cam.has_pose = true;
  cam.distortion = {-0.2, 0, 0, 0, 0};
  BallHint h;
  h.time_s = 1.0;
  h.ball_in_world = Vector3d(6, 0, 10);  // normalised image radius 0.6
  h.radius_m = 0.11;
  const std::optional<ExpectedBall> e = ExpectBall(h, cam, 1.0, 0.05, BallHintOptions());
  ASSERT_TRUE(e);
  camera::Camera no_lens = cam;
  no_lens.distortion.clear();
  EXPECT_LT(e->radius_px, 0.9 * *camera::SphereRadiusPx(no_lens, h.ball_in_world, h.radius_m));
  EXPECT_NEAR(e->radius_px, *camera::SphereRadiusPx(cam, h.ball_in_world, h.radius_m), 1e-9);
}

}  // namespace
}  // namespace fv::pipeline
