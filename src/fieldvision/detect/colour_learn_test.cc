#include "fieldvision/detect/colour_learn.h"

#include <gtest/gtest.h>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv {
namespace {

// Share of the pixels of `mask` (CV_8U) that the class selects.
double Selected(const ColourTable& t, const cv::Mat& bgr, const cv::Mat& mask) {
  const cv::Mat cls = t.ClassifyImage(bgr) & t.BallBit();
  return double(cv::countNonZero(cls & mask)) / std::max(1, cv::countNonZero(mask));
}

TEST(LearnColour, PinkBallFromARegionAndFromPoints) {
  const uint64_t seed = fv::testing::TestSeed(17);
  FV_SEED_TRACE(seed);
  Rng rng(seed);
  cv::Mat img = detect_testing::FieldImage(320, 240, rng);
  const cv::Vec3b pink(180, 105, 255);
  const Eigen::Vector2d c(rng.Uniform(100, 220), rng.Uniform(80, 160));
  const double r = 14;
  detect_testing::PaintDisc(img, c, r, pink);
  cv::Mat ball(img.size(), CV_8U, cv::Scalar(0));
  cv::circle(ball, cv::Point(cvRound(c.x()), cvRound(c.y())), int(r - 2), 255, cv::FILLED);
  cv::Mat rest(img.size(), CV_8U, cv::Scalar(255));
  cv::circle(rest, cv::Point(cvRound(c.x()), cvRound(c.y())), int(r + 2), 0, cv::FILLED);
  for (int mode = 0; mode < 2; ++mode) {
    SCOPED_TRACE(mode == 0 ? "roi" : "points");
    ColourLearnOptions o;
    if (mode == 0) {
      // A loose box: its inscribed ellipse holds grass too.
      o.roi = cv::Rect(int(c.x() - r - 7), int(c.y() - r - 7), int(2 * r + 14), int(2 * r + 14));
    } else {
      o.points = {c, c + Eigen::Vector2d(5, 3), c + Eigen::Vector2d(-6, -4),
                  c + Eigen::Vector2d(-3, 7)};
    }
    const ColourLearnResult res = LearnColour(img, o);
    EXPECT_GT(res.recall, 0.9) << res.Summary();
    EXPECT_LT(res.negative_rate, 0.002) << res.Summary();
    const ColourTable table(res.spec);
    EXPECT_GT(Selected(table, img, ball), 0.9) << res.Summary();
    EXPECT_LT(Selected(table, img, rest), 0.002) << res.Summary();
    EXPECT_EQ(res.overlay.size(), img.size());
    // The learned colour finds the ball.
    const BallDetector det(BallDetectorOptions{}, res.spec, nullptr, nullptr);
    const auto cands = det.Detect(img);
    ASSERT_FALSE(cands.empty());
    EXPECT_TRUE(cands.front().accepted) << cands.front().reason;
    EXPECT_LT((cands.front().centre_px - c).norm(), 0.3);
  }
}

TEST(LearnColour, AClassThatSelectsTheBackgroundIsBad) {
  const uint64_t seed = fv::testing::TestSeed(18);
  FV_SEED_TRACE(seed);
  Rng rng(seed);
  cv::Mat img = detect_testing::FieldImage(320, 240, rng);
  // A yellow ball on a wall of nearly its colour: whatever box is learned selects the wall too.
  img(cv::Rect(0, 0, 320, 140)).setTo(cv::Scalar(40, 200, 215));
  const Eigen::Vector2d c(160, 70);
  detect_testing::PaintDisc(img, c, 12, cv::Vec3b(30, 210, 230), 0.0);
  ColourLearnOptions o;
  o.roi = cv::Rect(140, 50, 40, 40);
  const ColourLearnResult res = LearnColour(img, o);
  EXPECT_TRUE(res.bad) << res.Summary();
  EXPECT_NE(res.Summary().find("BAD CLASS"), std::string::npos);
  // The clean pink ball of the test above is not.
  cv::Mat clean = detect_testing::FieldImage(320, 240, rng);
  detect_testing::PaintDisc(clean, c, 14, cv::Vec3b(180, 105, 255));
  o.roi = cv::Rect(140, 50, 40, 40);
  EXPECT_FALSE(LearnColour(clean, o).bad);
}

TEST(LearnColour, BadInputIsNamed) {
  cv::Mat img(100, 100, CV_8UC3, cv::Scalar(50, 140, 60));
  ColourLearnOptions o;
  EXPECT_THROW(LearnColour(img, o), Error);  // neither points nor region
  o.points = {Eigen::Vector2d(150, 10)};
  try {
    LearnColour(img, o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("outside the 100x100 frame"), std::string::npos);
  }
  EXPECT_THROW(ParsePoints("1,2;3", "--points"), Error);
  EXPECT_THROW(ParsePoints("a,b", "--points"), Error);
  EXPECT_EQ(ParsePoints("1,2; 3.5,4", "--points").size(), 2u);
  EXPECT_THROW(ParseRect("1,2,3", "--roi"), Error);
  EXPECT_EQ(ParseRect("1,2,3,4", "--roi"), cv::Rect(1, 2, 3, 4));
  EXPECT_THROW(ReadVideoFrame("/nonexistent/v.avi", 0), Error);
}

}  // namespace
}  // namespace fv
