#include "fieldvision/io/repeated_chroma.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/io/frame_source.h"
#include "fieldvision/io/io_testing.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::io {
namespace {

// A yellow disc of radius `r` at a sub-pixel centre on noisy green grass, drawn at 8x and
// shrunk (an anti-aliased outline).
cv::Mat Disc(cv::Size size, cv::Point2d centre, double r, util::Rng& rng) {
  constexpr int kScale = 8;
  cv::Mat big(size * kScale, CV_8UC3, cv::Scalar(50, 120, 55));
  cv::circle(big,
             cv::Point(static_cast<int>(centre.x * kScale), static_cast<int>(centre.y * kScale)),
             static_cast<int>(r * kScale), cv::Scalar(20, 200, 230), cv::FILLED, cv::LINE_AA);
  cv::Mat img;
  cv::resize(big, img, size, 0, 0, cv::INTER_AREA);
  cv::Mat noise(size, CV_16SC3);
  cv::RNG cv_rng(static_cast<uint64_t>(rng.UniformInt(1, 1 << 30)));
  cv_rng.fill(noise, cv::RNG::NORMAL, 0, 1.5);
  cv::Mat out;
  cv::add(img, noise, out, cv::noArray(), CV_8UC3);
  return out;
}

// Mean |Cr - Cr_reference| + |Cb - Cb_reference| over the pixels within 2 px of the outline.
double ChromaErrorAtOutline(const cv::Mat& bgr, const cv::Mat& reference, cv::Point2d c, double r) {
  cv::Mat a, b;
  cv::cvtColor(bgr, a, cv::COLOR_BGR2YCrCb);
  cv::cvtColor(reference, b, cv::COLOR_BGR2YCrCb);
  double sum = 0;
  int n = 0;
  for (int y = 0; y < a.rows; ++y) {
    for (int x = 0; x < a.cols; ++x) {
      if (std::abs(std::hypot(x + 0.5 - c.x, y + 0.5 - c.y) - r) > 2) continue;
      const cv::Vec3b p = a.at<cv::Vec3b>(y, x), q = b.at<cv::Vec3b>(y, x);
      sum += std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]);
      ++n;
    }
  }
  return sum / n;
}

TEST(RepeatedChroma, LayoutOfRepeatedSmoothAndFlatFrames) {
  const uint64_t seed = testing::TestSeed(3);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const cv::Mat frame = Disc({160, 120}, {80.3, 60.6}, 17.2, rng);
  EXPECT_EQ(MeasureChromaLayout(test_util::RepeatChroma2x2(frame)), ChromaLayout::kRepeated2x2);
  EXPECT_EQ(MeasureChromaLayout(frame), ChromaLayout::kOther);
  cv::Mat smooth;  // chroma decimated and upsampled bilinearly, as libjpeg does
  cv::resize(frame, smooth, {80, 60}, 0, 0, cv::INTER_AREA);
  cv::resize(smooth, smooth, frame.size(), 0, 0, cv::INTER_LINEAR);
  EXPECT_EQ(MeasureChromaLayout(smooth), ChromaLayout::kOther);
  EXPECT_EQ(MeasureChromaLayout(cv::Mat(120, 160, CV_8UC3, cv::Scalar(90, 90, 90))),
            ChromaLayout::kUnknown);
  EXPECT_EQ(MeasureChromaLayout(cv::Mat(1, 1, CV_8UC3, cv::Scalar(0, 0, 0))),
            ChromaLayout::kUnknown);
}

TEST(RepeatedChroma, UpsamplingPutsColourBackOnTheOutlineAndKeepsLuma) {
  const uint64_t seed = testing::TestSeed(5);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  for (int k = 0; k < 4; ++k) {
    SCOPED_TRACE(k);
    const cv::Point2d c(60 + rng.Uniform(0, 2), 50 + rng.Uniform(0, 2));
    const double r = rng.Uniform(5, 15);
    const cv::Mat truth = Disc({121, 101}, c, r, rng);  // odd size: a last block of its own
    const cv::Mat repeated = test_util::RepeatChroma2x2(truth);
    cv::Mat repaired = repeated.clone();
    UpsampleRepeatedChroma(&repaired);
    ASSERT_EQ(repaired.size(), truth.size());
    const double before = ChromaErrorAtOutline(repeated, truth, c, r);
    const double after = ChromaErrorAtOutline(repaired, truth, c, r);
    cv::Mat bilinear = repeated.clone();  // a range weight that weighs nothing
    UpsampleRepeatedChroma(&bilinear, {.luma_sigma = 1e6});
    const double plain = ChromaErrorAtOutline(bilinear, truth, c, r);
    // Chroma decimated to blocks cannot all come back (measured: 21-23 repeated, 17-19
    // re-upsampled, 28-30 bilinear): the luma's edges put it on the right side of the outline.
    EXPECT_LT(after, 0.9 * before) << "repeated " << before << " re-upsampled " << after;
    EXPECT_LT(after, 0.75 * plain) << "bilinear " << plain << " re-upsampled " << after;
    cv::Mat l0, l1, diff;
    cv::cvtColor(repeated, l0, cv::COLOR_BGR2GRAY);
    cv::cvtColor(repaired, l1, cv::COLOR_BGR2GRAY);
    cv::absdiff(l0, l1, diff);
    double most = 0;
    cv::minMaxLoc(diff, nullptr, &most);
    EXPECT_LE(most, 2.0);  // luma kept (rounding, and saturation of a channel)
  }
}

TEST(RepeatedChroma, AStreamIsRepairedOnlyWhenItsChromaIsRepeated) {
  util::Rng rng(7);
  const cv::Mat frame = Disc({96, 64}, {40.4, 30.2}, 9.3, rng);
  RepeatedChromaRepair smooth;
  cv::Mat a = frame.clone();
  smooth.Apply(&a);
  EXPECT_EQ(smooth.layout(), ChromaLayout::kOther);
  EXPECT_EQ(cv::norm(a, frame, cv::NORM_INF), 0.0);
  RepeatedChromaRepair repeated;
  cv::Mat flat(64, 96, CV_8UC3, cv::Scalar(50, 120, 55));
  repeated.Apply(&flat);  // says nothing: decided on a later frame
  EXPECT_EQ(repeated.layout(), ChromaLayout::kUnknown);
  cv::Mat b = test_util::RepeatChroma2x2(frame);
  const cv::Mat before = b.clone();
  repeated.Apply(&b);
  EXPECT_EQ(repeated.layout(), ChromaLayout::kRepeated2x2);
  EXPECT_GT(cv::norm(b, before, cv::NORM_INF), 0.0);
  RepeatedChromaRepair grey;  // never any colour: measured no longer after a while
  for (int i = 0; i < RepeatedChromaRepair::kMeasuredFrames; ++i) {
    cv::Mat g(64, 96, CV_8UC3, cv::Scalar(70, 70, 70));
    grey.Apply(&g);
    EXPECT_EQ(grey.layout(), i + 1 < RepeatedChromaRepair::kMeasuredFrames ? ChromaLayout::kUnknown
                                                                           : ChromaLayout::kOther);
  }
}

TEST(RepeatedChroma, OptionsAreChecked) {
  RepeatedChromaOptions o;
  o.luma_sigma = 0;
  EXPECT_NE(testing::ErrorOf([&] { o.Check(); }).find("luma_sigma"), std::string::npos);
  o = {};
  o.max_within_share = 1.5;
  EXPECT_NE(testing::ErrorOf([&] { o.Check(); }).find("max_within_share"), std::string::npos);
  o = {};
  o.skip_levels = -1;
  EXPECT_NE(testing::ErrorOf([&] { o.Check(); }).find("skip_levels"), std::string::npos);
  cv::Mat grey(8, 8, CV_8UC1, cv::Scalar(0));
  EXPECT_NE(testing::ErrorOf([&] { UpsampleRepeatedChroma(&grey); }).find("8-bit BGR"),
            std::string::npos);
}

// MPEG-4 video (4:2:0) through a frame source: OpenCV's reader repeats the chroma, the source
// does not.
TEST(RepeatedChroma, VideoFramesComeWithoutRepeatedChroma) {
  util::Rng rng(11);
  const std::string path = testing::TempDir() + "/disc.mp4";
  {
    cv::VideoWriter w(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), 25,
                      cv::Size(160, 120));
    if (!w.isOpened()) GTEST_SKIP() << "OpenCV cannot write MPEG-4 here";
    for (int i = 0; i < 5; ++i) w.write(Disc({160, 120}, {70.0 + 3 * i, 60.5}, 20, rng));
  }
  cv::VideoCapture capture(path, cv::CAP_FFMPEG);
  cv::Mat raw;
  ASSERT_TRUE(capture.read(raw));
  ASSERT_EQ(MeasureChromaLayout(raw), ChromaLayout::kRepeated2x2)
      << "OpenCV's reader no longer repeats chroma: the repair is never used";
  auto source = OpenFrameSource(path);
  EXPECT_NE(source->FramesNote().find("re-upsampled"), std::string::npos) << source->FramesNote();
  cv::Mat bgr;
  long long frame = 0;
  double t = 0;
  int frames = 0;
  while (source->Read(&bgr, &frame, &t)) {
    EXPECT_EQ(MeasureChromaLayout(bgr), ChromaLayout::kOther) << "frame " << frame;
    ++frames;
  }
  EXPECT_EQ(frames, 5);
  // Motion-JPEG (libjpeg interpolates its chroma): nothing to say.
  const std::string avi = testing::TempDir() + "/disc.avi";
  {
    cv::VideoWriter w(avi, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25,
                      cv::Size(160, 120));
    ASSERT_TRUE(w.isOpened());
    for (int i = 0; i < 3; ++i) w.write(Disc({160, 120}, {70.0 + 3 * i, 60.5}, 20, rng));
  }
  EXPECT_EQ(OpenFrameSource(avi)->FramesNote(), "");
}

}  // namespace
}  // namespace fv::io
