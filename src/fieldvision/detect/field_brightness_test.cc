#include "fieldvision/detect/field_brightness.h"

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

TEST(FieldBrightness, FieldValueIsTheGrassMedianAndNeedsField) {
  const uint64_t seed = fv::testing::TestSeed(71);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  const uint8_t field_bit = table.ClassBit("field");
  cv::Mat img = test_util::FieldImage(320, 240, rng);
  // Grass V 140 with darker stripes of 125; a robot and a wall do not count.
  cv::rectangle(img, cv::Rect(0, 0, 320, 60), cv::Scalar(200, 200, 200), cv::FILLED);
  cv::rectangle(img, cv::Rect(100, 100, 60, 60), cv::Scalar(20, 20, 20), cv::FILLED);
  const double v = FieldValue(img, table, field_bit);
  EXPECT_GE(v, 123.0);
  EXPECT_LE(v, 143.0);
  // Only the region asked for is read: the wall alone has no field of the class.
  FieldBrightnessOptions class_only;
  class_only.image_field.enabled = false;
  EXPECT_LT(FieldValue(img, table, field_bit, class_only, cv::Rect(0, 0, 320, 60)), 0.0);
  EXPECT_LT(FieldValue(img, table, 0, class_only), 0.0);  // no field class
  const cv::Mat grey(240, 320, CV_8UC3, cv::Scalar(128, 128, 128));
  EXPECT_LT(FieldValue(grey, table, field_bit, class_only), 0.0);
  // Without the class, the image's own field colour (image_field.h): the grass again.
  const double own = FieldValue(img, table, 0);
  EXPECT_GE(own, 123.0);
  EXPECT_LE(own, 143.0);
}

TEST(FieldBrightness, LitValueIsTheBrightPartOfTheDisc) {
  cv::Mat img(100, 100, CV_8UC3, cv::Scalar(10, 10, 10));
  // The upper 20 % of a disc of radius 20 bright (V 220), the rest V 90.
  cv::circle(img, {50, 50}, 20, cv::Scalar(0, 40, 90), cv::FILLED);
  cv::rectangle(img, cv::Rect(30, 30, 41, 8), cv::Scalar(0, 100, 220), cv::FILLED);
  cv::circle(img, {50, 50}, 21, cv::Scalar(10, 10, 10), 2);  // nothing outside the disc
  EXPECT_EQ(LitValue(img, {50, 50}, 20), 220.0);
  EXPECT_EQ(LitValue(img, {50, 60}, 8), 90.0);         // the lower part alone
  EXPECT_EQ(LitValue(img, {50.2, 34.1}, 0.3), 220.0);  // under a pixel: the pixel
  EXPECT_EQ(LitValue(img, {98, 50}, 6), 10.0);         // cut by the border: what is inside
  EXPECT_LT(LitValue(img, {-30, 50}, 6), 0.0);         // outside the image
  EXPECT_THROW(LitValue(img, {std::nan(""), 50}, 6), Error);
  FieldBrightnessOptions bad;
  bad.step_px = 0;
  EXPECT_THROW(bad.Check(), Error);
}

// Without a posed camera an orange LED glowing on a dark robot (a dim orange disc, V 120, on
// grass of V 140) passes the shape and colour checks but is darker than the field: rejected. A
// ball (V 255 on its lit side) is accepted; with the check off (ratio 0) the LED is accepted
// too.
TEST(FieldBrightness, TheDetectorRejectsADiscDarkerThanTheField) {
  const uint64_t seed = fv::testing::TestSeed(72);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  BallDetectorOptions on;
  BallDetectorOptions off = on;
  off.min_lit_field_ratio = 0.0;
  const BallDetector det_on(on, nullptr, nullptr), det_off(off, nullptr, nullptr);
  for (int trial = 0; trial < 4; ++trial) {
    cv::Mat img = test_util::FieldImage(320, 240, rng);
    const Eigen::Vector2d c(rng.Uniform(80, 240), rng.Uniform(120, 180));
    const double r = rng.Uniform(5, 9);
    cv::rectangle(img, cv::Rect(int(c.x() - 4 * r), int(c.y() - 3 * r), int(8 * r), int(6 * r)),
                  cv::Scalar(25, 25, 25), cv::FILLED);
    cv::Mat ball = img.clone();
    test_util::PaintDisc(img, c, r, cv::Vec3b(0, 55, 120), 0.8);
    test_util::PaintDisc(ball, c, r, test_util::kOrange, 0.8);
    const auto led_on = det_on.Detect(img);
    const auto led_off = det_off.Detect(img);
    const auto ball_on = det_on.Detect(ball);
    ASSERT_FALSE(led_on.empty());
    ASSERT_FALSE(led_off.empty());
    ASSERT_FALSE(ball_on.empty());
    SCOPED_TRACE("r " + std::to_string(r) + ": " + led_on.front().reason + " / " +
                 led_off.front().reason);
    EXPECT_TRUE(led_off.front().accepted);
    EXPECT_FALSE(led_on.front().accepted);
    EXPECT_NE(led_on.front().reason.find("darker than the field"), std::string::npos);
    EXPECT_TRUE(ball_on.front().accepted) << ball_on.front().reason;
  }
  BallDetectorOptions bad;
  bad.min_lit_field_ratio = -1;
  EXPECT_THROW(bad.Check(), Error);
}

}  // namespace
}  // namespace fv::detect
