#include "fieldvision/track/line_anchor.h"

#include <cmath>
#include <iostream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core/eigen.hpp>

#include "fieldvision/camera/opencv_camera.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/track/camera_motion.h"
#include "fieldvision/track/track_testing.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::track {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// The players scene's side camera at 640x480 with a 50 degree lens, without people.
synth::SceneSpec SideCamera(uint64_t seed) {
  synth::SceneSpec spec = synth::Preset("players", seed);
  synth::ResizeCameras(spec, 640, 480);
  spec.cameras[0].hfov_deg = 50;
  spec.people.clear();
  spec.num_frames = 1;
  return spec;
}

// A turned camera's view on the first one's undistorted pixels: K R0 Rf^T K^-1.
cv::Matx33d RotationHomography(const camera::Camera& first, const camera::Camera& frame) {
  cv::Matx33d r0, rf;
  cv::eigen2cv(Eigen::Matrix3d(first.cam_from_world.rotation), r0);
  cv::eigen2cv(Eigen::Matrix3d(frame.cam_from_world.rotation), rf);
  const cv::Matx33d k = camera::IntrinsicMatrix(first);
  return k * r0 * rf.t() * k.inv();
}

// The largest distance between where a and b take a 5x5 grid over the image's lower two thirds
// (the ground the side camera sees).
double ViewError(const cv::Matx33d& a, const cv::Matx33d& b) {
  return test_util::ViewError(a, b, 32, 608, 160, 460, 4);
}

// The first view moved by (dx, dy) pixels and turned by `deg` about its centre: drift.
cv::Matx33d Drift(double dx, double dy, double deg) {
  const double a = deg * M_PI / 180, c = std::cos(a), s = std::sin(a);
  const cv::Matx33d to_centre(1, 0, -319.5, 0, 1, -239.5, 0, 0, 1);
  const cv::Matx33d turn(c, -s, 0, s, c, 0, 0, 0, 1);
  return to_centre.inv() * cv::Matx33d(1, 0, dx, 0, 1, dy, 0, 0, 1) * turn * to_centre;
}

// A camera turned about its centre: the pose from its homography to the first view is its own
// (1e-9), and the ground plane's homography between the two poses is that homography.
TEST(LineAnchor, TurnedCameraPoseFromItsHomography) {
  testing::SeededRng rng(1);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const camera::Camera first = synth::SceneRenderer(SideCamera(rng.seed())).cameras()[0];
  const LineAnchor anchor(first, field);
  for (int trial = 0; trial < 20; ++trial) {
    camera::Camera turned = first;
    turned.cam_from_world.rotation =
        geometry::RotationFromRvec(Eigen::Vector3d(rng.Uniform(-0.2, 0.2), rng.Uniform(-0.8, 0.8),
                                                   rng.Uniform(-0.1, 0.1))) *
        first.cam_from_world.rotation;
    turned.cam_from_world.translation = -turned.cam_from_world.rotation * first.CentreInWorld();
    const cv::Matx33d h = RotationHomography(first, turned);
    const camera::Camera pose = anchor.FramePose(h * (trial % 2 == 0 ? 3.7 : -0.2));  // any scale
    EXPECT_LT((pose.cam_from_world.rotation - turned.cam_from_world.rotation).norm(), 1e-9);
    EXPECT_LT((pose.CentreInWorld() - turned.CentreInWorld()).norm(), 1e-9);
    EXPECT_LT(ViewError(anchor.GroundHomography(turned), h), 1e-6);
  }
}

// A camera moved and turned (a drone): the pose from its ground plane's homography to the first
// view is its own (1e-9), at any scale of the homography.
TEST(LineAnchor, MovedCameraPoseFromItsGroundHomography) {
  testing::SeededRng rng(2);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const camera::Camera first = synth::SceneRenderer(SideCamera(rng.seed())).cameras()[0];
  LineAnchorOptions moving;
  moving.refine.fix_centre = false;
  const LineAnchor anchor(first, field, moving);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d centre =
        first.CentreInWorld() +
        Eigen::Vector3d(rng.Uniform(-5, 5), rng.Uniform(-2, 2), rng.Uniform(-1, 3));
    camera::Camera moved = first;
    moved.cam_from_world = geometry::Rigid3d::LookAt(
        centre, Eigen::Vector3d(rng.Uniform(-5, 5), rng.Uniform(-2, 2), 0.0));
    const cv::Matx33d h = anchor.GroundHomography(moved);
    const camera::Camera pose = anchor.FramePose(h * (trial % 2 == 0 ? 2.5 : -0.3));
    EXPECT_LT((pose.cam_from_world.rotation - moved.cam_from_world.rotation).norm(), 1e-9);
    EXPECT_LT((pose.CentreInWorld() - moved.CentreInWorld()).norm(), 1e-9);
  }
}

// A turned camera's view registered with drift (moved 4-8 px and turned 0.5 degree on the first
// view, as a chain of flows drifts over grass) is pulled back onto the painted lines it sees:
// within 1 px over the ground it sees (seeds 1-20: drifted 6.0-13.0 px, held 0.03-0.26 px).
TEST(LineAnchor, DriftedViewIsHeldToTheLines) {
  testing::SeededRng rng(3);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  synth::SceneSpec spec = SideCamera(rng.seed());
  const camera::Camera first = synth::SceneRenderer(spec).cameras()[0];
  spec.cameras[0].look_at_m.x() += rng.Uniform(-5, 5);
  const synth::SceneRenderer scene(spec);
  const cv::Mat frame = scene.Render(0)[0];
  const cv::Matx33d truth = RotationHomography(first, scene.cameras()[0]);
  const double angle = rng.Uniform(0, 2 * M_PI), shift = rng.Uniform(4, 8);
  const cv::Matx33d drifted =
      Drift(shift * std::cos(angle), shift * std::sin(angle), rng.Uniform() < 0.5 ? 0.5 : -0.5) *
      truth;
  LineAnchor anchor(first, field);
  const auto held = anchor.Correct(frame, {}, drifted);
  ASSERT_TRUE(held.has_value()) << anchor.stats().Summary();
  const double before = ViewError(drifted, truth), after = ViewError(*held, truth);
  std::cout << "line anchor: view off by " << before << " px drifted, " << after
            << " px held to the lines; " << anchor.stats().Summary() << "\n";
  EXPECT_GT(before, 4.0);
  EXPECT_LT(after, 1.0);
  // Between keyframes a view on the lines is only checked; one off them is fitted.
  LineAnchor between(first, field);
  EXPECT_FALSE(between.Correct(frame, {}, truth, /*keyframe=*/false).has_value());
  EXPECT_EQ(between.stats().checked, 1);
  EXPECT_EQ(between.stats().tried, 0);
  const auto refitted = between.Correct(frame, {}, drifted, /*keyframe=*/false);
  ASSERT_TRUE(refitted.has_value()) << between.stats().Summary();
  EXPECT_LT(ViewError(*refitted, truth), 1.0);
  EXPECT_EQ(between.stats().tried, 1);
  // People's boxes over the whole frame leave no line pixels: the registered view is kept.
  EXPECT_FALSE(anchor.Correct(frame, {cv::Rect2d(0, 0, 640, 480)}, drifted).has_value());
}

// A frame wider than the work width (1280x960, searched at 960) is held as well as at full
// width: within 2 px over the ground it sees (1 px at 640x480).
TEST(LineAnchor, WideFramesAreSearchedAtTheWorkWidth) {
  testing::SeededRng rng(4);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  synth::SceneSpec spec = SideCamera(rng.seed());
  synth::ResizeCameras(spec, 1280, 960);
  const camera::Camera first = synth::SceneRenderer(spec).cameras()[0];
  spec.cameras[0].look_at_m.x() += rng.Uniform(-5, 5);
  const synth::SceneRenderer scene(spec);
  const cv::Mat frame = scene.Render(0)[0];
  const cv::Matx33d truth = RotationHomography(first, scene.cameras()[0]);
  const cv::Matx33d to_half(0.5, 0, -0.25, 0, 0.5, -0.25, 0, 0, 1);  // 1280x960 px to 640x480
  const cv::Matx33d drifted = to_half.inv() * Drift(4, -3, 0.5) * to_half * truth;
  for (const int width : {960, 1280}) {
    LineAnchorOptions o;
    o.work_width_px = width;
    LineAnchor anchor(first, field, o);
    const auto held = anchor.Correct(frame, {}, drifted);
    ASSERT_TRUE(held.has_value()) << anchor.stats().Summary();
    const double after =
        ViewError(to_half * *held * to_half.inv(), to_half * truth * to_half.inv());
    std::cout << "line anchor at 1280x960, lines found at " << width << " px wide: " << 2 * after
              << " px off\n";
    EXPECT_LT(2 * after, 2.0);
  }
}

// A frame without lines (grass only), a view too far off for the lines to hold it, a field
// without lines and a camera without a pose.
TEST(LineAnchor, WithoutLinesTheViewIsKept) {
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const camera::Camera first = synth::SceneRenderer(SideCamera(1)).cameras()[0];
  LineAnchor anchor(first, field);
  const cv::Mat grass(480, 640, CV_8UC3, cv::Scalar(40, 120, 40));
  EXPECT_FALSE(anchor.Correct(grass, {}, cv::Matx33d::eye()).has_value());
  const cv::Mat frame = synth::SceneRenderer(SideCamera(1)).Render(0)[0];
  EXPECT_FALSE(anchor.Correct(frame, {}, Drift(150, 0, 0)).has_value()) << anchor.stats().Summary();
  EXPECT_EQ(anchor.stats().anchored, 0);
  EXPECT_EQ(anchor.stats().tried, 2);
  field::FieldModel bare = field;
  bare.segments.clear();
  bare.arcs.clear();
  EXPECT_THAT([&] { LineAnchor(first, bare); },
              ThrowsMessage<Error>(HasSubstr("no painted lines")));
  camera::Camera unposed = first;
  unposed.has_pose = false;
  EXPECT_THAT([&] { LineAnchor(unposed, field); }, ThrowsMessage<Error>(HasSubstr("no pose")));
  LineAnchorOptions bad;
  bad.refit_above_px = std::nan("");
  EXPECT_THAT([&] { LineAnchor(first, field, bad); },
              ThrowsMessage<Error>(HasSubstr("refit_above_px")));
}

}  // namespace
}  // namespace fv::track
