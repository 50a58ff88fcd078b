#include "fieldvision/detect/background.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

// A static camera's frames: one field image with fresh noise each, a ball painted at a new place
// in each and, when `still` is set, a ball-sized disc at the same place in all.
struct Scene {
  cv::Mat base;
  std::vector<cv::Mat> frames;
  std::vector<Eigen::Vector2d> balls;
};

const Eigen::Vector2d kStill(250, 60);

Scene MakeScene(util::Rng& rng, int n, bool still) {
  Scene s;
  s.base = test_util::FieldImage(320, 240, rng, 0.0);
  for (int i = 0; i < n; ++i) {
    cv::Mat f = test_util::WithNoise(s.base, rng, 2.0);
    const Eigen::Vector2d c(30 + 260.0 * i / n, rng.Uniform(100, 200));
    test_util::PaintDisc(f, c, 8);
    if (still) test_util::PaintDisc(f, kStill, 8);
    s.frames.push_back(f);
    s.balls.push_back(c);
  }
  return s;
}

std::vector<cv::Mat> Reduced(const std::vector<cv::Mat>& frames, int scale) {
  std::vector<cv::Mat> out;
  for (const cv::Mat& f : frames) out.push_back(Background::Reduce(f, scale));
  return out;
}

TEST(Background, ABallThatCameIntoViewStandsApartAStillOneDoesNot) {
  const uint64_t seed = fv::testing::TestSeed(61);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  for (const int scale : {1, 2}) {
    SCOPED_TRACE(scale);
    const Scene s = MakeScene(rng, 7, /*still=*/true);
    BackgroundOptions o;
    o.scale = scale;
    const Background bg(Reduced(s.frames, scale), s.base.size(), o);
    ASSERT_TRUE(bg.usable()) << bg.Summary();
    EXPECT_LE(bg.noise(), 4) << bg.Summary();
    // The median leaves each frame's ball out and keeps the still disc.
    cv::Mat scene = s.base.clone();
    test_util::PaintDisc(scene, kStill, 8);
    const cv::Mat reduced_base = Background::Reduce(scene, scale);
    cv::Mat diff;
    cv::absdiff(bg.image(), reduced_base, diff);
    double worst = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
    EXPECT_LT(worst, 16) << "the background keeps a ball";
    // A new frame: the ball at a new place stands apart, the still disc does not, nor does bare
    // grass.
    cv::Mat frame = test_util::WithNoise(s.base, rng, 2.0);
    const Eigen::Vector2d ball(160, 120);
    test_util::PaintDisc(frame, ball, 8);
    test_util::PaintDisc(frame, kStill, 8);
    const BackgroundEvidence moving = bg.Compare(frame, ball, 8);
    EXPECT_TRUE(moving.apart) << moving.disc_share << " " << moving.ring_share;
    EXPECT_GT(moving.disc_share, 0.9);
    EXPECT_LT(moving.ring_share, 0.1);
    const BackgroundEvidence still = bg.Compare(frame, kStill, 8);
    EXPECT_FALSE(still.apart);
    EXPECT_LT(still.disc_share, 0.1);
    EXPECT_FALSE(bg.Compare(frame, Eigen::Vector2d(60, 200), 8).apart);
  }
}

TEST(Background, ALightChangeOrAMovingCameraGivesNoEvidence) {
  const uint64_t seed = fv::testing::TestSeed(62);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const Scene s = MakeScene(rng, 7, /*still=*/false);
  const Background bg(Reduced(s.frames, 2), s.base.size(), {});
  ASSERT_TRUE(bg.usable());
  // The sun comes out: the ball and everything around it are brighter.
  cv::Mat brighter = test_util::WithNoise(s.base, rng, 2.0);
  const Eigen::Vector2d ball(160, 120);
  test_util::PaintDisc(brighter, ball, 8);
  brighter += cv::Scalar::all(40);
  const BackgroundEvidence lit = bg.Compare(brighter, ball, 8);
  EXPECT_FALSE(lit.apart);
  EXPECT_GT(lit.ring_share, 0.5);
  // A camera that pans over stands and boards: its frames disagree, no background.
  cv::Mat stands(s.base.size(), CV_8UC3);
  test_util::FillNormal(stands, rng, 120, 60);
  cv::GaussianBlur(stands, stands, cv::Size(7, 7), 0);
  std::vector<cv::Mat> panned;
  for (int i = 0; i < 7; ++i) {
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 9.0 * i, 0, 1, 4.0 * i);
    cv::Mat f;
    cv::warpAffine(stands, f, shift, s.base.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    panned.push_back(f);
  }
  const Background moving(Reduced(panned, 2), s.base.size(), {});
  EXPECT_FALSE(moving.usable()) << moving.Summary();
  EXPECT_NE(moving.Summary().find("not usable"), std::string::npos);
  cv::Mat frame = s.frames[0].clone();
  test_util::PaintDisc(frame, ball, 8);
  EXPECT_FALSE(moving.Compare(frame, ball, 8).apart);
}

TEST(Background, ReadsOnlyInsideItsRegion) {
  const uint64_t seed = fv::testing::TestSeed(63);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const Scene s = MakeScene(rng, 5, /*still=*/false);
  const Background bg(Reduced(s.frames, 2), s.base.size(), {});
  cv::Mat frame = test_util::WithNoise(s.base, rng, 2.0);
  const Eigen::Vector2d ball(161.3, 118.6);
  test_util::PaintDisc(frame, ball, 7);
  const cv::Rect roi(120, 80, 81, 77);
  const BackgroundEvidence clean = bg.Compare(frame, ball, 7, roi);
  cv::Mat outside(frame.size(), CV_8UC3);
  test_util::FillNormal(outside, rng, 128, 80);
  frame(roi).copyTo(outside(roi));
  const BackgroundEvidence read = bg.Compare(outside, ball, 7, roi);
  EXPECT_TRUE(clean.apart);
  EXPECT_EQ(read.disc_share, clean.disc_share);
  EXPECT_EQ(read.ring_share, clean.ring_share);
  // A region too small for the ring: no evidence.
  EXPECT_FALSE(bg.Compare(frame, ball, 7, cv::Rect(150, 110, 20, 20)).apart);
}

TEST(Background, BadInputThrows) {
  util::Rng rng(1);
  const Scene s = MakeScene(rng, 3, false);
  const auto reduced = Reduced(s.frames, 2);
  EXPECT_NE(fv::testing::ErrorOf([&] {
              Background(std::vector<cv::Mat>{reduced[0], reduced[1]}, s.base.size(), {});
            }).find("at least 3 frames"),
            std::string::npos);
  EXPECT_NE(fv::testing::ErrorOf([&] {
              Background(Reduced(s.frames, 2), cv::Size(640, 480), {});
            }).find("160x120"),
            std::string::npos);
  BackgroundOptions o;
  o.scale = 3;
  EXPECT_NE(fv::testing::ErrorOf([&] { o.Check(); }).find("scale"), std::string::npos);
  o = {};
  o.samples = 2;
  EXPECT_NE(fv::testing::ErrorOf([&] { o.Check(); }).find("samples"), std::string::npos);
  const Background bg(Reduced(s.frames, 2), s.base.size(), {});
  // A frame of another size: no evidence, no error; a frame not BGR: an error.
  EXPECT_FALSE(bg.Compare(cv::Mat(10, 10, CV_8UC3, cv::Scalar::all(0)), {5, 5}, 2).apart);
  EXPECT_FALSE(bg.ChangedDisc(cv::Mat(10, 10, CV_8UC3, cv::Scalar::all(0)), {0, 0, 10, 10}));
  EXPECT_NE(fv::testing::ErrorOf([&] {
              bg.Compare(cv::Mat(240, 320, CV_8UC1), {5, 5}, 2);
            }).find("8-bit BGR"),
            std::string::npos);
  EXPECT_FALSE(bg.Compare(s.frames[0], {std::nan(""), 5}, 4).apart);
}

}  // namespace
}  // namespace fv::detect
