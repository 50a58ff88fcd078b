#include "fieldvision/track/hidden_feet.h"

#include <functional>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/track/bytetrack.h"
#include "fieldvision/track/track_testing.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::track {
namespace {

using test_util::PersonBox;
using test_util::SideCamera;

// A walker whose legs go behind someone nearer the camera for a second, with boxes a few
// percent off in height: the hidden rows' feet come back to the path (before: metres beyond it),
// the others keep theirs; boxes wider than the person (two people in one box) and boxes at the
// image's top edge (the head may be above it) are left alone.
TEST(HiddenFeet, HiddenLegsAreGivenBackTheirFeet) {
  testing::SeededRng rng(43);
  const camera::Camera cam = SideCamera();
  const double fps = 25;
  const double foot_offset_m = 0.2;
  std::vector<TrackRow> rows;
  std::vector<double> true_x;
  for (int f = 1; f <= 100; ++f) {
    const double x = -3.0 + 1.5 * (f - 1) / fps;
    const bool hidden = f >= 40 && f < 65;
    cv::Rect2d box = PersonBox(cam, x, 0.0, hidden ? 0.8 : 0.0);
    box.height *= 1.0 + rng.Uniform(-0.03, 0.03);
    if (f == 70) box.width *= 2.0;  // two people in one box
    if (f == 70) box.height *= 0.7;
    if (f == 80) {  // cut by the image's top edge: a short box whose top is not the head
      box.height *= 0.7;
      box.y = 0.0;
    }
    TrackRow r;
    r.frame = f;
    r.id = 3;
    r.box = box;
    const auto g = FootOnGround(cam, box, foot_offset_m);
    ASSERT_TRUE(g.has_value());
    r.x_m = g->x();
    r.y_m = g->y();
    rows.push_back(r);
    true_x.push_back(x);
  }
  const std::vector<TrackRow> before = rows;
  const int moved = MendHiddenFeet(rows, {}, cam, foot_offset_m, fps);
  EXPECT_EQ(moved, 25);
  for (size_t i = 0; i < rows.size(); ++i) {
    const bool hidden = rows[i].frame >= 40 && rows[i].frame < 65;
    SCOPED_TRACE("frame " + std::to_string(rows[i].frame));
    if (hidden) {
      EXPECT_GT(*before[i].y_m, 2.0);  // a foot 0.8 m up, mapped to the ground beyond the walker
      EXPECT_NEAR(*rows[i].y_m, foot_offset_m, 0.45);  // the box heights are 3 % off
      EXPECT_NEAR(*rows[i].x_m, true_x[i], 0.1);
    } else {
      EXPECT_EQ(*rows[i].x_m, *before[i].x_m);
      EXPECT_EQ(*rows[i].y_m, *before[i].y_m);
    }
  }
  // Off: nothing moves; without a pose nothing can.
  std::vector<TrackRow> again = before;
  HiddenFeetOptions off;
  off.enabled = false;
  EXPECT_EQ(MendHiddenFeet(again, {}, cam, foot_offset_m, fps, off), 0);
  camera::Camera unposed = cam;
  unposed.has_pose = false;
  EXPECT_EQ(MendHiddenFeet(again, {}, unposed, foot_offset_m, fps), 0);
  // A moving camera's rows (in the first frame's pixels) whose boxes reach their own frame's top
  // (frame_box) are left: the top edge is judged in the frame's pixels.
  const FrameBoxOf at_top = [](const TrackRow& r) { return cv::Rect2d(r.box.x, 0, 10, 10); };
  std::vector<TrackRow> moving = before;
  EXPECT_EQ(MendHiddenFeet(moving, {}, cam, foot_offset_m, fps, {}, at_top), 0);
  EXPECT_GT(MendHiddenFeet(moving, {}, cam, foot_offset_m, fps, {}, {}), 0);
  // Rows that are not measurements (filled across a gap) do not count for the height but are
  // moved too; so are the hidden rows at a track's end (the earlier heights' line reaches them).
  std::vector<bool> measured(again.size(), true);
  for (size_t i = 0; i < again.size(); ++i) {
    measured[i] = again[i].frame < 50 || again[i].frame > 53;
  }
  EXPECT_EQ(MendHiddenFeet(again, measured, cam, foot_offset_m, fps), 25);
  std::vector<TrackRow> end(before.begin(), before.begin() + 44);  // the track ends hidden
  EXPECT_EQ(MendHiddenFeet(end, {}, cam, foot_offset_m, fps), 5);
}

// A player sprinting at 8 m/s towards the camera, in full view: the box grows by half in a
// second. No row is taken for a hidden one, the first and last included (box heights alone,
// compared one-sided at a track's end, would call 16 of them short).
TEST(HiddenFeet, ASprinterTowardsTheCameraIsNotHidden) {
  const camera::Camera cam = SideCamera();
  const double fps = 25;
  std::vector<TrackRow> rows;
  for (int f = 1; f <= 60; ++f) {
    TrackRow r;
    r.frame = f;
    r.id = 1;
    r.box = PersonBox(cam, 1.0, 10.0 - 8.0 * (f - 1) / fps);
    const auto g = FootOnGround(cam, r.box, 0.2);
    ASSERT_TRUE(g.has_value());
    r.x_m = g->x();
    r.y_m = g->y();
    rows.push_back(r);
  }
  ASSERT_GT(rows.back().box.height, 1.5 * rows.front().box.height);
  EXPECT_EQ(MendHiddenFeet(rows, {}, cam, 0.2, fps), 0);
}

TEST(HiddenFeet, BadInputIsRefused) {
  std::vector<TrackRow> rows(2);
  const camera::Camera cam = SideCamera();
  EXPECT_THROW(MendHiddenFeet(rows, {true}, cam, 0.2, 25), Error);
  EXPECT_THROW(MendHiddenFeet(rows, {}, cam, 0.2, 0), Error);
  const std::vector<std::function<void(HiddenFeetOptions&)>> bad = {
      [](HiddenFeetOptions& o) { o.full_height_ratio = 1.5; },
      [](HiddenFeetOptions& o) { o.window_s = 0.0; },
      [](HiddenFeetOptions& o) { o.max_width_ratio = 0.5; }};
  for (const auto& make_bad : bad) {
    HiddenFeetOptions o;
    make_bad(o);
    EXPECT_THROW(o.Check(), Error);
    std::vector<TrackRow> none;
    EXPECT_THROW(MendHiddenFeet(none, {}, cam, 0.2, 25, o), Error);
  }
}

}  // namespace
}  // namespace fv::track
