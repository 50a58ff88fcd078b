#include "fieldvision/detect/camera_background.h"

#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

// A 30-frame video (MJPG unless told) of a static camera, a ball crossing it, each frame's number
// written as the grey level (8 x number) of a block in its top-left corner; "" when OpenCV cannot
// write that codec.
std::string WriteVideo(const std::string& path, util::Rng& rng, int frames = 30,
                       int fourcc = cv::VideoWriter::fourcc('M', 'J', 'P', 'G')) {
  const cv::Mat base = test_util::FieldImage(320, 240, rng, 2.0);
  cv::VideoWriter w(path, fourcc, 30.0, base.size());
  if (!w.isOpened()) return "";
  for (int i = 0; i < frames; ++i) {
    cv::Mat f = base.clone();
    test_util::PaintDisc(f, Eigen::Vector2d(20 + 9.0 * i, 150), 8);
    f(cv::Rect(0, 0, 32, 32)).setTo(cv::Scalar::all(8 * i));
    w.write(f);
  }
  return path;
}

TEST(CameraBackground, SamplesEvenlyAcrossTheWindowAndBuildsOnce) {
  const uint64_t seed = fv::testing::TestSeed(71);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const std::string video = WriteVideo(fv::testing::TempDir() + "/static.avi", rng);
  // Five samples of 30 frames: frames 0, 7, 15, 22, 29 (round(k * 29 / 4)); a 0.5 s window (15
  // frames at 30 fps): 0, 4, 7, 11, 14.
  for (const auto& [window_s, expected] :
       {std::pair{60.0, std::vector<int>{0, 7, 15, 22, 29}}, {0.5, {0, 4, 7, 11, 14}}}) {
    auto source = io::OpenFrameSource(video, {.encoded = true});
    const std::vector<cv::Mat> sampled = SampleFrames(source.get(), 5, window_s, 2);
    ASSERT_EQ(sampled.size(), expected.size());
    for (size_t k = 0; k < expected.size(); ++k) {
      EXPECT_EQ(sampled[k].size(), cv::Size(160, 120));
      const double level = cv::mean(sampled[k](cv::Rect(4, 4, 8, 8)))[0];
      EXPECT_NEAR(level / 8, expected[k], 0.3) << "sample " << k << ", window " << window_s;
    }
  }
  CameraBackgroundOptions o;
  o.background.samples = 5;
  auto cb = std::make_shared<CameraBackground>(video, o);
  EXPECT_EQ(cb->Summary(), CameraBackground::kNotNeeded);
  cb->Start();
  const BackgroundFn fn = CameraBackground::FnFor(cb);
  const Background* b = fn();
  ASSERT_NE(b, nullptr) << cb->Summary();
  EXPECT_EQ(fn(), b);  // built once
  EXPECT_NE(cb->Summary().find("from 5 frames"), std::string::npos) << cb->Summary();
}

// Videos whose frames do not skip without decoding (MPEG-4 part 2 here, as H.264) and PNG files
// are sampled as a Motion-JPEG video is: the same frames. Both get a background; the video's
// over decoded_window_s at most, none when that is 0.
TEST(CameraBackground, SamplesOtherCodecsAndImageFilesAlike) {
  const uint64_t seed = fv::testing::TestSeed(72);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const std::string dir = fv::testing::TempDir();
  const std::string mp4 =
      WriteVideo(dir + "/static.mp4", rng, 30, cv::VideoWriter::fourcc('m', 'p', '4', 'v'));
  if (mp4.empty()) GTEST_SKIP() << "OpenCV cannot write MPEG-4 here";
  const std::string pngs = dir + "/png";
  std::filesystem::create_directories(pngs);
  {
    auto source = io::OpenFrameSource(mp4, {.encoded = true});
    ASSERT_FALSE(source->encoded());
    ASSERT_FALSE(source->SkipsWithoutDecoding());
    cv::Mat bgr;
    long long frame = 0;
    double t = 0;
    for (int i = 0; source->Read(&bgr, &frame, &t); ++i) {
      cv::imwrite(fmt::format("{}/{:05d}.png", pngs, i), bgr);
    }
  }
  for (const std::string& video : {mp4, pngs + "/%05d.png"}) {
    for (const auto& [window_s, expected] :
         {std::pair{60.0, std::vector<int>{0, 7, 15, 22, 29}}, {0.5, {0, 4, 7, 11, 14}}}) {
      auto source = io::OpenFrameSource(video, {.encoded = true});
      const std::vector<cv::Mat> sampled = SampleFrames(source.get(), 5, window_s, 2);
      ASSERT_EQ(sampled.size(), 5u) << video;
      for (size_t k = 0; k < expected.size(); ++k) {
        const double level = cv::mean(sampled[k](cv::Rect(4, 4, 8, 8)))[0];
        EXPECT_NEAR(level / 8, expected[k], 0.5)
            << "sample " << k << " of " << video << ", window " << window_s;
      }
      // Not backwards, not beyond the end.
      EXPECT_FALSE(source->SeekFrame(3)) << video;
      EXPECT_FALSE(source->SeekFrame(30)) << video;
    }
    CameraBackgroundOptions o;
    o.background.samples = 5;
    CameraBackground cb(video, o);
    EXPECT_NE(cb.Get(), nullptr) << video << ": " << cb.Summary();
    EXPECT_EQ(cb.Summary().find("read in order") != std::string::npos, video == mp4)
        << cb.Summary();
  }
  CameraBackgroundOptions off;
  off.decoded_window_s = 0;
  CameraBackground none(mp4, off);
  EXPECT_EQ(none.Get(), nullptr);
  EXPECT_NE(none.Summary().find("not Motion-JPEG or image files"), std::string::npos)
      << none.Summary();
}

TEST(CameraBackground, NoBackgroundFromAMissingOrShortVideo) {
  util::Rng rng(1);
  CameraBackground missing(fv::testing::TempDir() + "/none.avi", {});
  EXPECT_EQ(missing.Get(), nullptr);
  EXPECT_NE(missing.Summary().find("no background: "), std::string::npos) << missing.Summary();
  EXPECT_NE(missing.Summary().find("none.avi"), std::string::npos) << missing.Summary();
  CameraBackground two(WriteVideo(fv::testing::TempDir() + "/two.avi", rng, 2), {});
  EXPECT_EQ(two.Get(), nullptr);
  EXPECT_NE(two.Summary().find("2 frames to sample"), std::string::npos) << two.Summary();
  CameraBackgroundOptions bad;
  bad.window_s = 0;
  EXPECT_NE(fv::testing::ErrorOf([&] { CameraBackground("x.avi", bad); }).find("window_s"),
            std::string::npos);
  bad.window_s = 60;
  bad.decoded_window_s = -1;
  EXPECT_NE(fv::testing::ErrorOf([&] { CameraBackground("x.avi", bad); }).find("decoded_window_s"),
            std::string::npos);
}

}  // namespace
}  // namespace fv::detect
