#include "fieldvision/detect/image_field.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/field_boundary.h"
#include "fieldvision/detect/field_brightness.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

// A phone photo of an SSL field with a teal carpet (hue about 190 deg: not the green preset),
// lighter towards the far edge at row `edge_y`, grey stands above it, a robot and a white line
// on it, and sensor noise.
cv::Mat TealSideView(int edge_y, util::Rng& rng) {
  cv::Mat img(480, 640, CV_8UC3);
  for (int y = 0; y < 480; ++y) {
    const double t = y < edge_y ? 0.0 : double(y - edge_y) / (480 - edge_y);  // 0 far, 1 near
    const cv::Vec3b carpet(static_cast<uint8_t>(165 - 30 * t), static_cast<uint8_t>(150 - 30 * t),
                           static_cast<uint8_t>(55 - 15 * t));
    img.row(y).setTo(y < edge_y ? cv::Scalar(185, 180, 175) : cv::Scalar(carpet));
  }
  cv::rectangle(img, cv::Rect(300, edge_y - 50, 60, 80), cv::Scalar(25, 25, 25), cv::FILLED);
  cv::line(img, {0, 400}, {639, 380}, cv::Scalar(235, 235, 235), 6);
  cv::Mat noise(img.size(), CV_16SC3);
  cv::RNG cv_rng(static_cast<uint64_t>(rng.Uniform(0, 1e9)));
  cv_rng.fill(noise, cv::RNG::NORMAL, 0.0, 2.5);
  cv::Mat noisy;
  img.convertTo(noisy, CV_16SC3);
  noisy += noise;
  noisy.convertTo(img, CV_8UC3);
  return img;
}

TEST(ImageField, ATealCarpetIsTheFieldAndBoundsIt) {
  const uint64_t seed = fv::testing::TestSeed(81);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const int edge_y = static_cast<int>(rng.Uniform(80, 160));
  const cv::Mat img = TealSideView(edge_y, rng);
  const std::optional<ImageFieldColour> colour = FindImageFieldColour(img, {});
  ASSERT_TRUE(colour.has_value());
  cv::Mat lab;
  cv::cvtColor(img, lab, cv::COLOR_BGR2Lab);
  // Most of the carpet, far and near, is held; none of the stands and the robot.
  const auto held = [&](const cv::Rect& r) {
    int n = 0;
    for (int y = r.y; y < r.y + r.height; ++y) {
      for (int x = r.x; x < r.x + r.width; ++x) n += colour->Holds(lab.at<cv::Vec3b>(y, x));
    }
    return double(n) / r.area();
  };
  EXPECT_GT(held(cv::Rect(0, edge_y + 2, 280, 200)), 0.9);    // left of the robot, above the line
  EXPECT_GT(held(cv::Rect(0, 420, 640, 60)), 0.9);            // the near carpet
  EXPECT_LT(held(cv::Rect(0, 0, 640, edge_y - 60)), 0.01);    // the stands
  EXPECT_LT(held(cv::Rect(305, edge_y - 45, 50, 40)), 0.01);  // the robot
  // The green preset's field class finds none of it; the boundary comes from the carpet itself.
  const ColourTable table(PresetColourSpec("orange"));
  const uint8_t field_bit = table.ClassBit("field");
  const FieldBoundary b = FindFieldBoundary(img, table, field_bit);
  ASSERT_TRUE(b.valid()) << b.Summary();
  for (int x = 8; x < 640; x += 32) EXPECT_NEAR(b.RowAt(x), edge_y, 2.0) << "x " << x;
  FieldBoundaryOptions off;
  off.image_field.enabled = false;
  EXPECT_FALSE(FindFieldBoundary(img, table, field_bit, off).valid());
  // The field brightness too: the carpet's median V (about 140-175), not the stands'.
  const double v = FieldValue(img, table, field_bit);
  EXPECT_GT(v, 130.0);
  EXPECT_LT(v, 180.0);
}

TEST(ImageField, NoCommonColourNoField) {
  const uint64_t seed = fv::testing::TestSeed(82);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  cv::Mat img(240, 320, CV_8UC3);
  cv::RNG cv_rng(seed);
  cv_rng.fill(img, cv::RNG::UNIFORM, 0, 256);  // no colour holds 40 % of it
  EXPECT_FALSE(FindImageFieldColour(img, {}).has_value());
  const ColourTable table(PresetColourSpec("orange"));
  EXPECT_FALSE(FindFieldBoundary(img, table, 0).valid());  // no class, no colour of its own
  EXPECT_LT(FieldValue(img, table, 0), 0.0);
  ImageFieldOptions bad;
  bad.samples = 0;
  EXPECT_THROW(bad.Check(), Error);
  bad = {};
  bad.lower_share = 0;
  EXPECT_THROW(bad.Check(), Error);
  bad = {};
  bad.max_delta_ab = -1;
  EXPECT_THROW(bad.Check(), Error);
}

}  // namespace
}  // namespace fv::detect
