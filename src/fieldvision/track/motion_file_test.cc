#include "fieldvision/track/motion_file.h"

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "fieldvision/camera/opencv_camera.h"
#include "fieldvision/track/camera_motion.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::track {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

camera::Camera Lens() {
  camera::Camera cam = camera::Camera::FromFov(640, 480, 60);
  cam.name = "phone";
  cam.distortion = {-0.1, 0.02, 0, 0, 0};
  cam.cam_from_world = geometry::Rigid3d::LookAt({0, -14, 8}, {0, 0, 0});
  cam.has_pose = true;
  return cam;
}

// A canvas written and read back maps every frame's pixels as before (within 1e-9 px), takes the
// pose of a camera file with the same lens and refuses one with another; a still camera's run
// removes an earlier motion file. Seeds 1-50 (the turns vary).
TEST(MotionFile, RoundTripAndLens) {
  testing::SeededRng rng(3);
  const camera::Camera lens = Lens();
  ViewCanvas canvas(lens, 0.75);
  for (int t = 0; t < 5; ++t) {
    cv::Matx33d q;
    cv::Rodrigues(cv::Vec3d(rng.Uniform(-0.05, 0.05), rng.Uniform(-0.3, 0.3), 0), q);
    const cv::Matx33d k = camera::IntrinsicMatrix(lens);
    canvas.AddFrame(k * q * k.inv());
  }
  const std::string dir = fv::testing::TempDir();
  const std::string tracks = dir + "/TRACKS.csv";
  EXPECT_THAT(SaveMotionFor(tracks, &canvas), HasSubstr("TRACKS.csv.motion.json"));
  const ViewCanvas back = ReadMotionFile(MotionPathFor(tracks));
  ASSERT_EQ(back.frames(), 5);
  EXPECT_EQ(back.size(), canvas.size());
  EXPECT_FALSE(back.camera().has_pose);
  for (int t = 0; t < 5; ++t) {
    const auto a = canvas.ToCanvas(t, {100, 400}), b = back.ToCanvas(t, {100, 400});
    ASSERT_TRUE(a && b);
    EXPECT_NEAR(a->x, b->x, 1e-9);
    EXPECT_NEAR(a->y, b->y, 1e-9);
  }
  EXPECT_TRUE(ReadMotionFile(MotionPathFor(tracks), &lens).camera().has_pose);
  camera::Camera other = lens;
  other.fx *= 1.01;
  EXPECT_THAT([&] { ReadMotionFile(MotionPathFor(tracks), &other); },
              ThrowsMessage<Error>(HasSubstr("registered through another lens")));
  // Tracks of a 632 px wide video through a 640 px camera file (an encoder's padding, which
  // players fitted away) are read with that camera file; 16 px more is another camera.
  camera::Camera narrow = lens;
  narrow.width = 632;
  ViewCanvas narrow_canvas(narrow, 0.5);
  narrow_canvas.AddFrame(cv::Matx33d::eye());
  const std::string narrow_tracks = dir + "/NARROW.csv";
  SaveMotionFor(narrow_tracks, &narrow_canvas);
  const ViewCanvas fitted = ReadMotionFile(MotionPathFor(narrow_tracks), &lens);
  EXPECT_EQ(fitted.lens().width, 632);
  EXPECT_TRUE(fitted.camera().has_pose);
  camera::Camera wider = lens;
  wider.width = 656;
  EXPECT_THROW(ReadMotionFile(MotionPathFor(narrow_tracks), &wider), Error);
  EXPECT_THAT(SaveMotionFor(tracks, nullptr), HasSubstr("removed"));
  EXPECT_FALSE(std::filesystem::exists(MotionPathFor(tracks)));
  EXPECT_EQ(SaveMotionFor(tracks, nullptr), "");
}

// A malformed motion file: one error naming the file and what is wrong.
TEST(MotionFile, MalformedFilesAreRefused) {
  const std::string dir = fv::testing::TempDir();
  const auto write = [&](const std::string& text) {
    std::ofstream(dir + "/m.json") << text;
    return dir + "/m.json";
  };
  const std::string head =
      R"({"format": "fieldvision camera motion 1", "width": 640, "height": 480, "fx": 500, )"
      R"("fy": 500, "cx": 319.5, "cy": 239.5, "distortion": [], "canvas_margin": 1, )";
  EXPECT_THAT([&] { ReadMotionFile(write("{")); },
              ThrowsMessage<Error>(HasSubstr("is not valid JSON")));
  EXPECT_THAT([&] { ReadMotionFile(write(head + R"("first_from_frame": []})")); },
              ThrowsMessage<Error>(HasSubstr("first_from_frame has no frame")));
  EXPECT_THAT([&] { ReadMotionFile(write(head + R"("first_from_frame": [[1, 0, 0]]})")); },
              ThrowsMessage<Error>(HasSubstr("first_from_frame[0]")));
  EXPECT_THAT(
      [&] {
        ReadMotionFile(write(head + R"("first_from_frame": [[1,0,0,0,1,0,0,0,1]], "x": 1})"));
      },
      ThrowsMessage<Error>(HasSubstr("unknown key 'x'")));
  EXPECT_THAT([&] { ReadMotionFile(write(R"({"format": "other"})")); },
              ThrowsMessage<Error>(HasSubstr("format must be")));
  EXPECT_THAT([&] { ReadMotionFile(dir + "/none.json"); },
              ThrowsMessage<Error>(HasSubstr("does not exist")));
}

}  // namespace
}  // namespace fv::track
