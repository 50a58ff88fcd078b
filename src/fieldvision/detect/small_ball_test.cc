// Balls of 1.5..2.8 px radius on grass, blurred and JPEG-compressed with 4:2:0 chroma (no pixel
// keeps the ball's colour) are found with their centre and size; plain grass and a white line
// give nothing; the detector takes them only where small balls are possible (mode).
#include "fieldvision/detect/small_ball.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

using Eigen::Vector2d;

TEST(SmallBall, MixedPixelBallsAreFoundAndGrassIsNot) {
  const uint64_t seed = fv::testing::TestSeed(11);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  const SmallBallOptions o;
  BallDetectorOptions on;
  on.small.mode = "on";
  const BallDetector det(on, nullptr, nullptr);
  int found = 0, small = 0, trials = 0;
  std::string misses;
  for (int trial = 0; trial < 12; ++trial) {
    cv::Mat img = test_util::FieldImage(224, 224, rng);
    const double r = rng.Uniform(1.6, 2.8);
    const Vector2d c(rng.Uniform(20, 204), rng.Uniform(20, 204));
    test_util::PaintDisc(img, c, r, test_util::kOrange, 0.3);
    cv::GaussianBlur(img, img, {0, 0}, 0.7);
    img = test_util::JpegRoundTrip(img, 75);
    ++trials;
    const auto cands = det.Detect(img);
    if (cands.empty() || !cands.front().accepted) {
      misses += " r " + std::to_string(r) + ": " + (cands.empty() ? "none" : cands.front().reason);
      continue;
    }
    // Pixel centres are at integer coordinates: the disc painted at c is centred there.
    const double err = (cands.front().centre_px - c).norm();
    if (err > 1.0) {
      misses += " r " + std::to_string(r) + ": " + std::to_string(err) + " px off;";
      continue;
    }
    ++found;
    small += cands.front().small;
    EXPECT_NEAR(cands.front().radius_px, r, 0.5 * r + 0.3) << "r " << r;
  }
  // At least 8 of the 12 for 29 of seeds 1-30; 7 at seed 9, whose misses are all under 1.9 px.
  // Fails at seed 61 of 1-100: 6 found, the 6 misses (r 1.6-2.6 px) without any candidate.
  EXPECT_GE(found, trials - 5) << misses;
  EXPECT_GT(small, 0);  // the smallest ones only by the small-ball stage
  // Grass with a white line: nothing of the ball's colour, however it is unmixed.
  for (int trial = 0; trial < 4; ++trial) {
    cv::Mat img = test_util::FieldImage(224, 224, rng);
    cv::line(img, {0, 100 + 10 * trial}, {223, 120 + 10 * trial}, cv::Scalar(235, 235, 235), 3,
             cv::LINE_AA);
    img = test_util::JpegRoundTrip(img, 75);
    EXPECT_TRUE(FindSmallBalls(img, table, table.BallBit(), {0, 0, 224, 224}, {}, o).empty());
  }
}

// Grass with a ball of 1.6 px at `c` and, when `dark_disc`, a dark orange disc of 9 px elsewhere,
// JPEG-compressed.
cv::Mat GrassWithASmallBall(util::Rng& rng, const Vector2d& c, bool dark_disc) {
  cv::Mat img = test_util::FieldImage(224, 224, rng);
  test_util::PaintDisc(img, c, 1.6, test_util::kOrange, 0.3);
  if (dark_disc) test_util::PaintDisc(img, {160.0, 150.0}, 9.0, cv::Vec3b(0, 45, 100), 0.3);
  return test_util::JpegRoundTrip(img, 75);
}

TEST(SmallBall, DetectorTakesThemOnlyWhereSmallBallsArePossible) {
  testing::SeededRng rng(12);
  const Vector2d c(101.3, 80.6);
  const cv::Mat img = GrassWithASmallBall(rng, c, false);
  BallDetectorOptions on;
  on.small.mode = "on";
  const auto with = BallDetector(on, nullptr, nullptr).Detect(img);
  ASSERT_FALSE(with.empty());
  ASSERT_TRUE(with.front().accepted) << with.front().reason;
  EXPECT_TRUE(with.front().small);
  EXPECT_LT((with.front().centre_px - c).norm(), 1.0);
  // auto (the default) without a camera: taken, on the grass (field_surround.h).
  const auto automatic = BallDetector(BallDetectorOptions{}, nullptr, nullptr).Detect(img);
  ASSERT_FALSE(automatic.empty());
  EXPECT_TRUE(automatic.front().accepted) << automatic.front().reason;
  EXPECT_TRUE(automatic.front().small);
  BallDetectorOptions off;
  off.small.mode = "off";
  EXPECT_TRUE(BallDetector(off, nullptr, nullptr).Detect(img).empty());
}

// A blob stage candidate that a later check rejects (a dark orange disc, darker than the field:
// no lit ball) leaves no accepted candidate: the small ball is looked for then.
TEST(SmallBall, LookedForWhenEveryBlobCandidateIsRejected) {
  testing::SeededRng rng(13);
  const Vector2d c(101.3, 80.6);
  const cv::Mat img = GrassWithASmallBall(rng, c, true);
  const auto cands = BallDetector(BallDetectorOptions{}, nullptr, nullptr).Detect(img);
  ASSERT_FALSE(cands.empty());
  EXPECT_TRUE(cands.front().accepted) << cands.front().reason;
  EXPECT_TRUE(cands.front().small);
  EXPECT_LT((cands.front().centre_px - c).norm(), 1.0);
  const auto disc = std::find_if(cands.begin(), cands.end(), [](const BallCandidate& b) {
    return (b.centre_px - Vector2d(160.0, 150.0)).norm() < 3.0;
  });
  ASSERT_NE(disc, cands.end());
  EXPECT_FALSE(disc->accepted);
  EXPECT_NE(disc->reason.find("darker than the field"), std::string::npos) << disc->reason;
}

TEST(SmallBall, OptionsAreChecked) {
  SmallBallOptions o;
  o.mode = "sometimes";
  EXPECT_THROW(o.Check(), Error);
  o = SmallBallOptions{};
  o.inner_box_px = 6;
  EXPECT_THROW(o.Check(), Error);
  o = SmallBallOptions{};
  o.extensions = {0.5};
  EXPECT_THROW(o.Check(), Error);
}

}  // namespace
}  // namespace fv::detect
