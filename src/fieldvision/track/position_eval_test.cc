#include "fieldvision/track/position_eval.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "fieldvision/track/bytetrack.h"
#include "fieldvision/track/track_testing.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::track {
namespace {

using test_util::PersonBox;
using test_util::SideCamera;

TrackRow Row(int frame, int id, const cv::Rect2d& box) {
  TrackRow r;
  r.frame = frame;
  r.id = id;
  r.box = box;
  return r;
}

// Two annotated walkers; the estimate follows them with positions off by known distances (seeded
// random 0-0.5 m), one stretch of boxes without legs, a false box and a missed frame. The ground
// truth's positions come from its boxes through the camera: matched rows score exactly the
// offsets given, the short rows apart. The scores hold for any seed (no threshold depends on the
// draw).
TEST(PositionEval, ScoresTheOffsetsGivenAndTheShortRowsApart) {
  testing::SeededRng rng(7);
  const camera::Camera cam = SideCamera();
  std::vector<TrackRow> gt, est;
  std::vector<double> offsets, short_offsets;
  for (int f = 1; f <= 40; ++f) {
    for (int id = 1; id <= 2; ++id) {
      const double x = (id == 1 ? -4.0 : 3.0) + 0.05 * f;
      const double y = id == 1 ? -2.0 : 4.0;
      gt.push_back(Row(f, id, PersonBox(cam, x, y)));
      if (id == 2 && f == 30) continue;  // missed
      const bool short_box = id == 1 && f >= 10 && f < 15;
      TrackRow e = Row(f + 1, 10 + id, PersonBox(cam, x, y, short_box ? 0.4 : 0.0));  // 0-based + 1
      const double d = rng.Uniform(0.0, 0.5);
      const double angle = rng.Uniform(0.0, 6.28);
      const auto foot = FootOnGround(cam, gt.back().box, 0.2);
      ASSERT_TRUE(foot.has_value());
      e.x_m = foot->x() + d * std::cos(angle);
      e.y_m = foot->y() + d * std::sin(angle);
      est.push_back(e);
      (short_box ? short_offsets : offsets).push_back(d);
    }
  }
  est.push_back(Row(5 + 1, 99, PersonBox(cam, 8.0, 0.0)));  // a false box far from everyone
  est.back().x_m = 8.0;
  est.back().y_m = 0.0;
  PlaceFeet(cam, 0.2, &gt);
  PositionEvalOptions o;
  o.frame_offset = -1;
  o.iou_threshold = 0.3;
  const PositionErrors p = EvaluatePositions(gt, est, o);
  EXPECT_EQ(p.gt_boxes, 80);
  EXPECT_EQ(p.matched, 79);
  EXPECT_EQ(p.without_position, 0);
  ASSERT_EQ(p.errors_m.size(), 79u);
  ASSERT_EQ(p.short_errors_m.size(), 5u);
  std::vector<double> all = offsets;
  all.insert(all.end(), short_offsets.begin(), short_offsets.end());
  std::sort(all.begin(), all.end());
  std::vector<double> got = p.errors_m;
  std::sort(got.begin(), got.end());
  for (size_t i = 0; i < all.size(); ++i) EXPECT_NEAR(got[i], all[i], 1e-9) << i;
  std::sort(short_offsets.begin(), short_offsets.end());
  got = p.short_errors_m;
  std::sort(got.begin(), got.end());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], short_offsets[i], 1e-9) << i;
  EXPECT_NE(p.Summary().find("79 of 80 annotated boxes matched"), std::string::npos) << p.Summary();
}

// Rows without positions are counted, not scored; a ground truth row the camera cannot place
// (its foot above the horizon) keeps none; a camera without a pose and bad options are refused.
TEST(PositionEval, RowsWithoutPositionsAndBadInput) {
  const camera::Camera cam = SideCamera();
  std::vector<TrackRow> gt = {Row(1, 1, PersonBox(cam, 0, 0)), Row(1, 2, {600, -400, 40, 100})};
  PlaceFeet(cam, 0.2, &gt);
  EXPECT_TRUE(gt[0].x_m.has_value());
  EXPECT_FALSE(gt[1].x_m.has_value());
  std::vector<TrackRow> est = {gt[0], gt[1]};
  est[0].x_m.reset();
  est[0].y_m.reset();
  const PositionErrors p = EvaluatePositions(gt, est);
  EXPECT_EQ(p.matched, 2);
  EXPECT_EQ(p.without_position, 2);
  EXPECT_TRUE(p.errors_m.empty());

  camera::Camera unposed = cam;
  unposed.has_pose = false;
  EXPECT_THROW(PlaceFeet(unposed, 0.2, &gt), Error);
  PositionEvalOptions bad;
  bad.iou_threshold = 0;
  EXPECT_THROW(EvaluatePositions(gt, est, bad), Error);
  bad = {};
  bad.short_height_ratio = std::nan("");
  EXPECT_THROW(EvaluatePositions(gt, est, bad), Error);
}

// A moving camera's ground truth: a person standing still, seen 40 px further left in the second
// frame because the view moved 40 px right, is placed at the same field point in both frames
// through the canvas (within 1e-6 m) as the first frame's box through the camera; a row of a frame
// beyond the canvas keeps no position.
TEST(PositionEval, MovingCameraFeetPlacedThroughTheCanvas) {
  const camera::Camera cam = SideCamera();
  const cv::Rect2d box = PersonBox(cam, 3.0, 1.0);
  std::vector<TrackRow> gt = {Row(1, 1, box), Row(2, 1, box - cv::Point2d(40, 0)), Row(3, 1, box)};
  ViewCanvas canvas(cam, 0.5);
  canvas.AddFrame(cv::Matx33d::eye());
  canvas.AddFrame(cv::Matx33d(1, 0, 40, 0, 1, 0, 0, 0, 1));  // the first view's from the second's
  PlaceFeet(canvas, 0.2, &gt);
  std::vector<TrackRow> still = {Row(1, 1, box)};
  PlaceFeet(cam, 0.2, &still);
  ASSERT_TRUE(still[0].x_m && gt[0].x_m && gt[1].x_m);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(*gt[i].x_m, *still[0].x_m, 1e-6) << "frame " << i + 1;
    EXPECT_NEAR(*gt[i].y_m, *still[0].y_m, 1e-6) << "frame " << i + 1;
  }
  EXPECT_FALSE(gt[2].x_m.has_value());
}

}  // namespace
}  // namespace fv::track
