#include "fieldvision/camera/frame_size.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::camera {
namespace {

using ::testing::HasSubstr;

// The Pose2Sim demo's cam01: its chessboard frames and the Qualisys file are 1088 wide, its video
// 1080 (H.264 codes 1088 and crops the padding at the right).
TEST(FrameSize, AnEncodersCroppedPaddingIsTakenOffTheCamera) {
  Camera cam = Camera::FromFov(1088, 1920, 40);
  cam.cx = 533.0;
  const Camera before = cam;
  const std::string note =
      FitCameraToFrames(cam, "camera file 'cam01.yaml'", 1080, 1920, "video 'v.mp4'");
  EXPECT_THAT(note, HasSubstr("cam01.yaml' is for 1088x1920 images, video 'v.mp4' is 1080x1920"));
  EXPECT_THAT(note, HasSubstr("cropped off at the right"));
  EXPECT_EQ(cam.width, 1080);
  EXPECT_EQ(cam.height, 1920);
  EXPECT_EQ(cam.fx, before.fx);
  EXPECT_EQ(cam.cx, before.cx);
  EXPECT_EQ(cam.cy, before.cy);
  // Landscape: the bottom rows.
  Camera wide = Camera::FromFov(1920, 1088, 60);
  EXPECT_THAT(FitCameraToFrames(wide, "camera 'c'", 1920, 1080, "video 'v.mp4'"),
              HasSubstr("bottom"));
  EXPECT_EQ(wide.height, 1080);
  // Both sides padded (a square video).
  Camera square = Camera::FromFov(1088, 1088, 60);
  EXPECT_THAT(FitCameraToFrames(square, "camera 'c'", 1080, 1080, "video 'v.mp4'"),
              HasSubstr("right and bottom"));
  // The same size: nothing to say.
  EXPECT_EQ(FitCameraToFrames(wide, "camera 'c'", 1920, 1080, "video 'v.mp4'"), "");
}

TEST(FrameSize, OtherSizesAreRefusedNamingBoth) {
  const auto error_of = [](int cam_w, int cam_h, int w, int h) {
    Camera cam = Camera::FromFov(cam_w, cam_h, 60);
    const std::string e = fv::testing::ErrorOf(
        [&] { FitCameraToFrames(cam, "camera file 'c.yaml'", w, h, "video 'v.mp4'"); });
    EXPECT_EQ(cam.width, cam_w);  // left as it was
    return e;
  };
  EXPECT_THAT(error_of(640, 480, 64, 48),
              HasSubstr("camera file 'c.yaml' is for 640x480 images but video 'v.mp4' is 64x48"));
  EXPECT_NE(error_of(1090, 1920, 1080, 1920), "");  // 1090 is not whole blocks
  EXPECT_NE(error_of(1088, 1920, 1072, 1920), "");  // 16 px: a whole block is no padding
  EXPECT_NE(error_of(1088, 1090, 1080, 1080), "");  // one side padded, the other not
  EXPECT_NE(error_of(1080, 1920, 1088, 1920), "");  // frames larger than the camera
  EXPECT_TRUE(IsCroppedPadding(Camera::FromFov(1920, 1088, 60), 1920, 1080));
  EXPECT_FALSE(IsCroppedPadding(Camera::FromFov(1920, 1080, 60), 1920, 1080));
}

}  // namespace
}  // namespace fv::camera
