#include "fieldvision/detect/field_boundary.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/dnn_ball.h"
#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

// A photo from the field's side: grey stands above row `edge_y`, the field below it with a
// white line, a dark robot standing on the far edge and one in front, and sensor noise.
cv::Mat SideView(int edge_y, util::Rng& rng) {
  cv::Mat img = test_util::FieldImage(640, 480, rng);
  img(cv::Rect(0, 0, 640, edge_y)).setTo(cv::Scalar(90, 95, 100));
  cv::rectangle(img, cv::Rect(300, edge_y - 60, 70, 90), cv::Scalar(30, 30, 30), cv::FILLED);
  cv::rectangle(img, cv::Rect(100, 300, 80, 120), cv::Scalar(25, 25, 25), cv::FILLED);
  cv::line(img, {0, 400}, {639, 380}, cv::Scalar(235, 235, 235), 6);
  return img;
}

uint8_t FieldBit(const ColourTable& table) { return table.ClassBit("field"); }

TEST(FieldBoundary, FollowsTheFieldsFarEdgeAcrossRobotsAndLines) {
  const uint64_t seed = fv::testing::TestSeed(61);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const int edge_y = static_cast<int>(rng.Uniform(60, 130));  // above the image's far line
  const cv::Mat img = SideView(edge_y, rng);
  const ColourTable table(PresetColourSpec("orange"));
  const FieldBoundary b = FindFieldBoundary(img, table, FieldBit(table));
  ASSERT_TRUE(b.valid()) << b.Summary();
  for (int x = 0; x < 640; x += 16) {
    // The robot on the edge (columns 300..369) is bridged by the columns beside it.
    EXPECT_NEAR(b.RowAt(x + 0.5), edge_y, 1.5) << "column " << x;
  }
  EXPECT_GT(b.Above(200, edge_y - 30), 25);
  EXPECT_LT(b.Above(200, edge_y + 30), -25);
}

// Something of the field's colour in the stands (a green shirt) does not lift the edge: the
// grey below it outweighs it.
TEST(FieldBoundary, AGreenShirtInTheStandsIsNotTheField) {
  const uint64_t seed = fv::testing::TestSeed(62);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  cv::Mat img = SideView(140, rng);
  cv::rectangle(img, cv::Rect(400, 20, 40, 60), cv::Scalar(50, 140, 60), cv::FILLED);
  const ColourTable table(PresetColourSpec("orange"));
  const FieldBoundary b = FindFieldBoundary(img, table, FieldBit(table));
  ASSERT_TRUE(b.valid());
  EXPECT_NEAR(b.RowAt(420), 140, 1.5);
}

TEST(FieldBoundary, NoFieldNoBoundaryAndNothingOutsideTheRegionIsRead) {
  const uint64_t seed = fv::testing::TestSeed(63);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  const cv::Mat grey(240, 320, CV_8UC3, cv::Scalar(120, 120, 120));
  FieldBoundaryOptions class_only;
  class_only.image_field.enabled = false;
  const FieldBoundary none = FindFieldBoundary(grey, table, FieldBit(table), class_only);
  EXPECT_FALSE(none.valid());
  EXPECT_LT(none.Above(10, 10), 0);  // nothing is above a missing boundary
  EXPECT_EQ(none.Summary(), "no field boundary");
  // By its own colour (image_field.h) a grey image is all field: nothing lies above its top.
  const FieldBoundary all = FindFieldBoundary(grey, table, FieldBit(table));
  ASSERT_TRUE(all.valid());
  EXPECT_EQ(all.RowAt(100), 0.0);
  // The field only in the region's columns: outside them the image is grey, and the boundary
  // found is the region's own.
  cv::Mat img = SideView(200, rng);
  img(cv::Rect(0, 0, 320, 480)).setTo(cv::Scalar(120, 120, 120));
  const FieldBoundary half =
      FindFieldBoundary(img, table, FieldBit(table), class_only, cv::Rect(400, 100, 200, 300));
  ASSERT_TRUE(half.valid());
  EXPECT_NEAR(half.RowAt(500), 200, 1.5);
  EXPECT_THROW(FieldBoundary({1, 1}, {2, 3}), Error);
  EXPECT_THROW(FieldBoundary({}, {}), Error);
  FieldBoundaryOptions bad;
  bad.columns = 1;
  EXPECT_THROW(bad.Check(), Error);
}

// Without a posed camera, a disc above the field's edge needs off_field_min_score or to be a
// whole disc; on the field, or with the check off, it is accepted.
TEST(FieldBoundary, TheDetectorRejectsADiscAboveTheFieldBelowTheScore) {
  const uint64_t seed = fv::testing::TestSeed(64);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const Eigen::Vector2d above(rng.Uniform(450, 560), rng.Uniform(60, 120));
  const Eigen::Vector2d on(rng.Uniform(450, 560), rng.Uniform(300, 360));
  const Eigen::Vector2d small(rng.Uniform(60, 200), rng.Uniform(60, 120));
  cv::Mat img = SideView(200, rng);
  test_util::PaintDisc(img, above, 10);
  test_util::PaintDisc(img, on, 10);
  test_util::PaintDisc(img, small, 3);
  BallDetectorOptions o;
  o.off_field_min_score = 1.0;  // scores stay below 1: only whole discs above the edge accepted
  const BallDetector whole(o, nullptr, nullptr);
  int whole_above = 0, whole_small = 0, small_seen = 0;
  for (const BallCandidate& c : whole.Detect(img)) {
    if ((c.centre_px - above).norm() < 2) whole_above += c.accepted;
    if ((c.centre_px - small).norm() < 2) {
      ++small_seen;
      whole_small += c.accepted;
      EXPECT_NE(c.reason.find("not a whole disc"), std::string::npos) << c.reason;
    }
  }
  EXPECT_EQ(whole_above, 1);  // a ball in the air, unhidden
  EXPECT_EQ(small_seen, 1);
  // "both" marks the rejected ones above the edge (MarkOffField): the small disc, not the one on
  // the field.
  std::vector<BallCandidate> marked = whole.Detect(img);
  MarkOffField(whole.OffFieldBoundary(img), &marked);
  for (const BallCandidate& c : marked) {
    if ((c.centre_px - small).norm() < 2) EXPECT_TRUE(c.off_field);
    if ((c.centre_px - on).norm() < 2) EXPECT_FALSE(c.off_field);
  }
  EXPECT_EQ(whole_small, 0);         // too small to judge its shape
  o.off_field_min_radius_px = 1000;  // no whole disc: every candidate above the edge rejected
  const BallDetector strict(o, nullptr, nullptr);
  int on_accepted = 0, above_seen = 0;
  for (const BallCandidate& c : strict.Detect(img)) {
    if ((c.centre_px - on).norm() < 2) on_accepted += c.accepted;
    if ((c.centre_px - above).norm() < 2) {
      ++above_seen;
      EXPECT_FALSE(c.accepted);
      EXPECT_NE(c.reason.find("above the field's edge"), std::string::npos) << c.reason;
    }
  }
  EXPECT_EQ(on_accepted, 1);
  EXPECT_EQ(above_seen, 1);
  EXPECT_NEAR(strict.OffFieldBoundary(img).RowAt(500), 200, 1.5);
  o.off_field_min_score = 0;
  const BallDetector off(o, nullptr, nullptr);
  EXPECT_FALSE(off.OffFieldBoundary(img).valid());
  int accepted = 0;
  for (const BallCandidate& c : off.Detect(img)) accepted += c.accepted;
  EXPECT_EQ(accepted, 3);
  o.off_field_min_score = 1.5;
  EXPECT_THROW(o.Check(), Error);
  o.off_field_min_score = 0.6;
  o.off_field_min_visible = -0.1;
  EXPECT_THROW(o.Check(), Error);
}

// Two accepted discs without a posed camera: the one on the field ranks first, even where the
// one above the field's edge (a lamp, a logo, a whole disc) scores higher.
TEST(FieldBoundary, AnAcceptedDiscOnTheFieldRanksBeforeOneAboveIt) {
  const uint64_t seed = fv::testing::TestSeed(65);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const Eigen::Vector2d above(rng.Uniform(450, 560), rng.Uniform(60, 120));
  const Eigen::Vector2d on(rng.Uniform(450, 560), rng.Uniform(300, 360));
  cv::Mat img = SideView(200, rng);
  test_util::PaintDisc(img, above, 14);
  test_util::PaintDisc(img, on, 9);
  // The disc on the field half hidden by a robot: a lower score than the whole one above.
  cv::rectangle(img, cv::Rect(static_cast<int>(on.x()) - 20, static_cast<int>(on.y()) + 2, 40, 20),
                cv::Scalar(25, 25, 25), cv::FILLED);
  BallDetectorOptions o;
  const BallDetector detector(o, nullptr, nullptr);
  const std::vector<BallCandidate> ranked = detector.Detect(img);
  const BallCandidate* above_c = nullptr;
  for (const BallCandidate& c : ranked) {
    if ((c.centre_px - above).norm() < 2) above_c = &c;
  }
  ASSERT_NE(above_c, nullptr);
  ASSERT_TRUE(above_c->accepted) << above_c->reason;
  ASSERT_FALSE(ranked.empty());
  EXPECT_TRUE(ranked.front().accepted);
  EXPECT_LT((ranked.front().centre_px - on).norm(), 3.0)
      << "first " << ranked.front().centre_px.transpose() << " score " << ranked.front().score
      << "; above-field disc score " << above_c->score;
  EXPECT_LT(ranked.front().score, above_c->score);  // the order is not the scores'
}

}  // namespace
}  // namespace fv::detect
