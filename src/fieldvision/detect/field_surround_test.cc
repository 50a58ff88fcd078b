// A small spot on the grass or on a carpet the field class misses (its own colour) is on the
// field; the same spot as an LED on a black robot or a mark on a white board is not, and the
// detector without a camera takes the one and rejects the others.
#include "fieldvision/detect/field_surround.h"

#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

using Eigen::Vector2d;

// A 224 x 224 frame of grass with a black robot and a white board on it and a small orange spot
// (radius 2.2 px, blurred) at `spot`.
cv::Mat SpotScene(const Vector2d& spot, util::Rng& rng) {
  cv::Mat img = test_util::FieldImage(224, 224, rng);
  cv::rectangle(img, cv::Rect(20, 140, 40, 40), cv::Scalar(25, 25, 28), cv::FILLED);      // robot
  cv::rectangle(img, cv::Rect(150, 140, 50, 30), cv::Scalar(230, 232, 235), cv::FILLED);  // board
  test_util::PaintDisc(img, spot, 2.2, test_util::kOrange, 0.3);
  cv::GaussianBlur(img, img, {0, 0}, 0.6);
  return test_util::JpegRoundTrip(img, 80);
}

TEST(FieldSurround, ASpotOnTheGrassIsOnTheFieldOnARobotOrABoardItIsNot) {
  const uint64_t seed = fv::testing::TestSeed(91);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  const uint8_t field = table.ClassBit("field");
  const Vector2d grass(rng.Uniform(80, 100), rng.Uniform(60, 80));
  const Vector2d robot(40, 160), board(175, 155);
  for (const auto& [where, at, on_field] :
       {std::tuple{"grass", grass, true}, std::tuple{"robot", robot, false},
        std::tuple{"board", board, false}}) {
    const cv::Mat img = SpotScene(at, rng);
    const double share = FieldShareAround(img, table, field, nullptr, at, 2.2);
    if (on_field) {
      EXPECT_GT(share, 0.9) << where;
    } else {
      EXPECT_LT(share, 0.1) << where;
    }
    // The detector without a camera (small balls "auto", the default): the spot on the grass is
    // a ball; the LED and the mark are small spots off the field.
    const auto cands = BallDetector(BallDetectorOptions{}, nullptr, nullptr).Detect(img);
    bool any_near = false, accepted_near = false;
    std::string why;
    for (const auto& c : cands) {
      if ((c.centre_px - at).norm() >= 2.0) continue;
      any_near = true;
      accepted_near = accepted_near || c.accepted;
      if (c.small) why = c.reason;
    }
    ASSERT_TRUE(any_near) << where << ": no candidate at the spot";
    EXPECT_EQ(accepted_near, on_field) << where;
    if (!on_field && !why.empty()) {
      EXPECT_NE(why.find("off the field"), std::string::npos) << why;
    }
    // With the check off every spot is taken.
    BallDetectorOptions no_check;
    no_check.small_field.min_share = 0.0;
    const auto all = BallDetector(no_check, nullptr, nullptr).Detect(img);
    ASSERT_FALSE(all.empty()) << where;
    EXPECT_TRUE(all.front().accepted) << where << ": " << all.front().reason;
  }
}

TEST(FieldSurround, ACarpetTheFieldClassMissesIsFieldByItsOwnColour) {
  // A grey-teal carpet (not the green preset's field class) with the spot on it.
  cv::Mat img(224, 224, CV_8UC3, cv::Scalar(150, 140, 70));
  test_util::PaintDisc(img, Vector2d(100, 150), 2.2, test_util::kOrange, 0.3);
  const ColourTable table(PresetColourSpec("orange"));
  const uint8_t field = table.ClassBit("field");
  EXPECT_LT(FieldShareAround(img, table, field, nullptr, {100, 150}, 2.2), 0.1);
  const std::optional<ImageFieldColour> own = FindImageFieldColour(img, {});
  ASSERT_TRUE(own.has_value());
  EXPECT_GT(FieldShareAround(img, table, field, &*own, {100, 150}, 2.2), 0.9);
  // The detector's FieldShare falls back on that colour, looked for once per frame; on grass the
  // class suffices and the image is not searched.
  const BallDetector detector(BallDetectorOptions{}, nullptr, nullptr);
  BallDetector::ImageFieldCache cache;
  EXPECT_GT(detector.FieldShare(img, {}, {100, 150}, 2.2, 0.5, &cache), 0.9);
  EXPECT_TRUE(cache.has_value());
  cv::Mat grass(224, 224, CV_8UC3, cv::Scalar(50, 140, 60));
  BallDetector::ImageFieldCache unused;
  EXPECT_GT(detector.FieldShare(grass, {}, {100, 150}, 2.2, 0.5, &unused), 0.9);
  EXPECT_FALSE(unused.has_value());
  const auto cands = BallDetector(BallDetectorOptions{}, nullptr, nullptr).Detect(img);
  ASSERT_FALSE(cands.empty());
  EXPECT_TRUE(cands.front().accepted) << cands.front().reason;
}

// Only the ring's pixels in the search region count (a tracking window: the frame outside it may
// not even be decoded).
TEST(FieldSurround, OnlyTheRegionIsRead) {
  cv::Mat img(60, 60, CV_8UC3, cv::Scalar(50, 140, 60));  // grass
  img.colRange(33, 60).setTo(cv::Scalar(0, 0, 0));        // right of the window: not field
  const ColourTable table(PresetColourSpec("orange"));
  const uint8_t field = table.ClassBit("field");
  const Eigen::Vector2d spot(30, 30);
  EXPECT_LT(FieldShareAround(img, table, field, nullptr, spot, 2.0), 0.9);
  const cv::Rect window(0, 0, 33, 60);
  EXPECT_DOUBLE_EQ(FieldShareAround(img, table, field, nullptr, spot, 2.0, {}, window), 1.0);
  EXPECT_LT(FieldShareAround(img, table, field, nullptr, spot, 2.0, {}, cv::Rect(50, 0, 5, 5)),
            0.0);
  const BallDetector detector(BallDetectorOptions{}, nullptr, nullptr);
  BallDetector::ImageFieldCache cache;
  EXPECT_DOUBLE_EQ(detector.FieldShare(img, window, spot, 2.0, 0.5, &cache), 1.0);
}

TEST(FieldSurround, BadInputAndARingOutsideTheImage) {
  const cv::Mat img(50, 50, CV_8UC3, cv::Scalar(50, 140, 60));
  const ColourTable table(PresetColourSpec("orange"));
  const uint8_t field = table.ClassBit("field");
  EXPECT_LT(FieldShareAround(img, table, field, nullptr, {-30, -30}, 2.0), 0.0);
  EXPECT_THROW(FieldShareAround(img, table, field, nullptr, {std::nan(""), 3}, 2.0), Error);
  EXPECT_THROW(FieldShareAround(img, table, field, nullptr, {3, 3}, -1.0), Error);
  EXPECT_THROW(FieldShareAround(cv::Mat(5, 5, CV_8UC1), table, field, nullptr, {3, 3}, 1.0), Error);
  FieldSurroundOptions o;
  o.width_px = 0.5;
  EXPECT_THROW(o.Check(), Error);
  o = FieldSurroundOptions{};
  o.min_share = 1.5;
  EXPECT_THROW(o.Check(), Error);
}

}  // namespace
}  // namespace fv::detect
