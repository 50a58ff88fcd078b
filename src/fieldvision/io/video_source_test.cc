#include "fieldvision/io/video_source.h"

#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/io/io_testing.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::io {
namespace {

cv::Mat NumberedFrame(int i, int w = 64, int h = 48) {
  cv::Mat m(h, w, CV_8UC3, cv::Scalar(10 * i, 255 - 10 * i, 100));
  return m;
}

TEST(VideoSource, ImagePatternGlobAndFolderInOrder) {
  const std::string dir = testing::TempDir();
  for (int i = 0; i < 5; ++i) cv::imwrite(fmt::format("{}/{:05d}.png", dir, i), NumberedFrame(i));
  for (const std::string& spec : {dir + "/%05d.png", dir + "/*.png", dir}) {
    SCOPED_TRACE(spec);
    auto src = VideoSource::Open(spec, {.fps = 25.0});
    EXPECT_EQ(src->frame_count(), 5);
    EXPECT_EQ(src->width(), 64);
    Frame f;
    int n = 0;
    while (src->Read(f)) {
      EXPECT_EQ(f.index, n);
      EXPECT_DOUBLE_EQ(f.time_s, n / 25.0);
      EXPECT_EQ(f.bgr.at<cv::Vec3b>(0, 0)[0], 10 * n);
      ++n;
    }
    EXPECT_EQ(n, 5);
  }
}

// A numbered sequence with a frame missing is an error naming the missing frame, not a clip cut
// short there; one that ends is just its frames.
TEST(VideoSource, AGapInANumberedSequenceIsAnError) {
  const std::string dir = testing::TempDir() + "/gap";
  std::filesystem::create_directories(dir);
  for (int i : {0, 1, 3}) cv::imwrite(fmt::format("{}/{:05d}.png", dir, i), NumberedFrame(i));
  const std::string error =
      testing::ErrorOf([&] { VideoSource::Open(dir + "/%05d.png", {.fps = 25.0}); });
  EXPECT_NE(error.find("00002.png' is missing"), std::string::npos) << error;
  EXPECT_NE(error.find("00003.png"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  std::filesystem::remove(fmt::format("{}/{:05d}.png", dir, 3));
  EXPECT_EQ(VideoSource::Open(dir + "/%05d.png", {.fps = 25.0})->frame_count(), 2);
}

// Still photos (a folder, a glob, one image, whatever its name) against a camera's frames (a
// numbered sequence, a video file): what `--detector auto` decides by.
TEST(VideoSource, StillImagesAreToldFromACamerasFrames) {
  const std::string dir = testing::TempDir() + "/stills";
  std::filesystem::create_directories(dir);
  for (int i = 0; i < 3; ++i) cv::imwrite(fmt::format("{}/{:05d}.png", dir, i), NumberedFrame(i));
  cv::imwrite(dir + "/50%.png", NumberedFrame(7));
  std::ofstream(dir + "/notes.txt") << "not an image\n";
  EXPECT_TRUE(IsStillImageInput(dir));
  EXPECT_TRUE(IsStillImageInput(dir + "/*.png"));
  EXPECT_TRUE(IsStillImageInput(dir + "/00001.png"));
  EXPECT_TRUE(IsStillImageInput(dir + "/50%.png"));
  EXPECT_FALSE(IsStillImageInput(dir + "/%05d.png"));
  EXPECT_FALSE(IsStillImageInput(dir + "/notes.txt"));
  EXPECT_FALSE(IsStillImageInput(dir + "/*.jpg"));  // matches nothing
  EXPECT_FALSE(IsStillImageInput("rtsp://camera/stream"));
}

TEST(VideoSource, MjpgFileFramesAndTimes) {
  const std::string path = testing::TempDir() + "/v.avi";
  {
    cv::VideoWriter w(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 50.0, cv::Size(64, 48));
    ASSERT_TRUE(w.isOpened());
    for (int i = 0; i < 7; ++i) w.write(NumberedFrame(i));
  }
  auto src = VideoSource::Open(path);
  EXPECT_EQ(src->frame_count(), 7);
  EXPECT_NEAR(src->fps(), 50.0, 1e-6);
  Frame f;
  int n = 0;
  while (src->Read(f)) {
    EXPECT_EQ(f.index, n);
    EXPECT_NEAR(f.time_s, n / 50.0, 1e-3);
    ++n;
  }
  EXPECT_EQ(n, 7);
}

// One image file is a sequence of one, decoded as a folder's images are (libjpeg for a JPEG, not
// FFmpeg, whose chroma upsampling differs): `detect` on one photo sees eval detect's pixels.
TEST(VideoSource, OneJpegImageGivesImreadsPixels) {
  const std::string path = testing::TempDir() + "/one.jpg";
  cv::Mat bgr(48, 64, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(bgr, cv::RNG::UNIFORM, 0, 256);  // chroma that changes from pixel to pixel
  ASSERT_TRUE(cv::imwrite(path, bgr));
  const cv::Mat expected = cv::imread(path, cv::IMREAD_COLOR);
  auto src = VideoSource::Open(path);
  EXPECT_EQ(src->frame_count(), 1);
  Frame f;
  ASSERT_TRUE(src->Read(f));
  ASSERT_EQ(f.bgr.size(), expected.size());
  EXPECT_EQ(cv::norm(f.bgr, expected, cv::NORM_INF), 0.0);
  EXPECT_FALSE(src->Read(f));
}

TEST(VideoSource, TruncatedVideoFailsAtItsEndNamingTheFrames) {
  const std::string path = test_util::WriteTruncatedMjpg(testing::TempDir() + "/cut.avi", 0.5);
  auto src = VideoSource::Open(path);
  EXPECT_EQ(src->frame_count(), 16);
  Frame f;
  int n = 0;
  try {
    while (src->Read(f)) ++n;
    ADD_FAILURE() << "the truncated video ended after " << n << " frames without an error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cut.avi"), std::string::npos) << what;
    EXPECT_NE(what.find(fmt::format("after {} of the 16 frames", n)), std::string::npos) << what;
  }
  EXPECT_LT(n, 16);
}

TEST(VideoSource, FileNamesWithPatternCharactersAreFiles) {
  const std::string dir = testing::TempDir();
  for (const std::string name : {"100%.avi", "a*b.avi", "c?.avi"}) {
    SCOPED_TRACE(name);
    const std::string path = fmt::format("{}/{}", dir, name);
    {
      cv::VideoWriter w(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0, cv::Size(64, 48));
      ASSERT_TRUE(w.isOpened());
      for (int i = 0; i < 3; ++i) w.write(NumberedFrame(i));
    }
    auto src = VideoSource::Open(path);
    EXPECT_EQ(src->frame_count(), 3);
    Frame f;
    int n = 0;
    while (src->Read(f)) ++n;
    EXPECT_EQ(n, 3);
  }
}

TEST(VideoSource, BadInputsNameTheInput) {
  const std::string dir = testing::TempDir();
  auto expect_error = [](const std::string& spec, const std::string& word) {
    try {
      VideoSource::Open(spec);
      ADD_FAILURE() << "no error for " << spec;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    }
  };
  expect_error(dir + "/missing.avi", "missing.avi");
  std::ofstream(dir + "/corrupt.avi") << "this is not a video at all";
  expect_error(dir + "/corrupt.avi", "corrupt.avi");
  expect_error(dir + "/none_%05d.png", "none_%05d.png");
  // A field width no frame name has is no pattern (printing a thousand names took an hour).
  expect_error(dir + "/%999999999d.png", "%999999999d.png");
  std::ofstream(dir + "/broken.jpg") << "not a JPEG";
  expect_error(dir + "/broken.jpg", "image '" + dir + "/broken.jpg' cannot be read");
  // A sequence whose later frame is unreadable fails at that frame, naming it.
  cv::imwrite(dir + "/s_00000.png", NumberedFrame(0));
  std::ofstream(dir + "/s_00001.png") << "broken";
  auto src = VideoSource::Open(dir + "/s_%05d.png");
  Frame f;
  EXPECT_TRUE(src->Read(f));
  EXPECT_THROW(src->Read(f), Error);
}

TEST(VideoSource, CameraSizeMismatch) {
  const std::string dir = testing::TempDir();
  cv::imwrite(dir + "/00000.png", NumberedFrame(0));
  auto src = VideoSource::Open(dir + "/%05d.png");
  camera::Camera cam = camera::Camera::FromFov(640, 480, 60);
  try {
    src->FitCamera(cam, "cam.yaml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cam.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("640x480"), std::string::npos);
  }
  cam = camera::Camera::FromFov(64, 48, 60);
  EXPECT_EQ(src->FitCamera(cam, "cam.yaml"), "");
}

}  // namespace
}  // namespace fv::io
