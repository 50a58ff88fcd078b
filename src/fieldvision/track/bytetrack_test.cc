#include "fieldvision/track/bytetrack.h"

#include <map>
#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/track/bytetrack_internal.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::track {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

struct Walker {
  double x, y, vx, vy;
};

// People crossing each other: detections with noise, misses and low scores while occluded, plus
// clutter; the tracker must keep one id per person. A limit of the tracker: at 2 of seeds 1-100
// (36 and 52) a crossing swaps ids (5 switches, IDF1 0.88).
TEST(ByteTracker, KeepsIdsThroughCrossingsAndMisses) {
  fv::testing::SeededRng rng(11);
  std::vector<Walker> people;
  for (int i = 0; i < 6; ++i) {
    // Pairs walk towards each other on nearby rows and cross in the middle.
    const int pair = i / 2;
    const double y = 100 + 60 * pair + rng.Uniform(-5, 5);
    const bool left = i % 2 == 0;
    people.push_back({left ? 50.0 : 650.0, y, left ? 4.0 : -4.0, rng.Uniform(-0.3, 0.3)});
  }
  ByteTracker tracker(TrackerOptions{}, nullptr);
  std::vector<TrackRow> gt, est;
  const int frames = 150;
  for (int f = 0; f < frames; ++f) {
    std::vector<Detection> dets;
    for (int i = 0; i < 6; ++i) {
      auto& p = people[i];
      const double x = p.x + p.vx * f, y = p.y + p.vy * f;
      const cv::Rect2d box(x, y, 30, 80);
      gt.push_back({f, i + 1, box, 1.0, {}, {}});
      // Near the crossing the one behind (odd) is partly hidden: low score or missed.
      const bool crossing = std::abs(x - 350) < 30;
      double score = rng.Uniform(0.6, 0.95);
      if (crossing && i % 2 == 1) score = rng.Uniform() < 0.5 ? 0.0 : rng.Uniform(0.25, 0.45);
      if (rng.Uniform() < 0.05) score = 0.0;  // random misses
      if (score <= 0) continue;
      dets.push_back({cv::Rect2d(x + rng.Normal(0, 1.5), y + rng.Normal(0, 1.5),
                                 30 + rng.Normal(0, 1), 80 + rng.Normal(0, 2)),
                      score});
    }
    if (rng.Uniform() < 0.1) {  // clutter
      dets.push_back({cv::Rect2d(rng.Uniform(0, 700), 400, 30, 80), rng.Uniform(0.2, 0.5)});
    }
    for (const auto& s : tracker.Update(dets, cv::Mat())) {
      est.push_back({f, s.id, s.box, s.score, {}, {}});
    }
  }
  const MotMetrics m = EvaluateMot(gt, est);
  EXPECT_EQ(m.id_switches, 0) << m.Summary();
  EXPECT_GT(m.idf1, 0.9) << m.Summary();
  EXPECT_GT(m.mota, 0.85) << m.Summary();
}

// Two people in different shirts walk side by side, so close that their boxes overlap and the
// noisy detections alone often fit either; the torso colours keep each id on its person.
TEST(ByteTracker, AppearanceKeepsIdsOfPeopleWalkingSideBySide) {
  const uint64_t seed = fv::testing::TestSeed(12);
  FV_SEED_TRACE(seed);
  const cv::Scalar shirts[2] = {cv::Scalar(30, 30, 200), cv::Scalar(200, 60, 30)};
  auto run = [&](double appearance_weight) {
    util::Rng rng(seed);
    TrackerOptions o;
    o.appearance_weight = appearance_weight;
    ByteTracker tracker(o, nullptr);
    std::vector<TrackRow> gt, est;
    for (int f = 0; f < 120; ++f) {
      cv::Mat frame(240, 640, CV_8UC3, cv::Scalar(90, 120, 90));
      std::vector<Detection> dets;
      for (int i = 0; i < 2; ++i) {
        // They sway towards and away from each other while walking right.
        const double x = 60 + 3.0 * f + (i == 0 ? 0 : 22) + 6 * std::sin(0.3 * f + 3 * i);
        const cv::Rect2d box(x, 80, 30, 80);
        gt.push_back({f, i + 1, box, 1.0, {}, {}});
        cv::rectangle(frame, cv::Rect(box.x, box.y, 30, 45), shirts[i], cv::FILLED);
        cv::rectangle(frame, cv::Rect(box.x, box.y + 45, 30, 35), cv::Scalar(40, 40, 40),
                      cv::FILLED);
        // Drawn one by one: the order of a call's arguments is the compiler's (GCC drew the
        // second first, clang the first), and so were the noise and the test's outcome.
        const double dy = rng.Normal(0, 2);
        const double dx = rng.Normal(0, 5);
        dets.push_back({cv::Rect2d(x + dx, 80 + dy, 30, 80), rng.Uniform(0.6, 0.9)});
      }
      for (const auto& s : tracker.Update(dets, frame)) {
        est.push_back({f, s.id, s.box, s.score, {}, {}});
      }
    }
    return EvaluateMot(gt, est, {0.3});
  };
  const MotMetrics with = run(0.5);
  const MotMetrics without = run(0.0);
  // Seeds 1-20: no switch for 17, 1-2 for seeds 2, 6 and 15 (each with a detection left
  // unmatched for a frame: 1-2 misses, one fragmentation). A limit of the tracker: at 6 of seeds
  // 1-100 (25, 39, 51, 56, 75, 80) the walk loses the ids for a while (IDF1 0.70-0.94, up to 4
  // switches): a track that took the other person's detection keeps that person's colours and
  // a third track takes turns with it (over the 100 walks 34 switches with appearance, 358
  // without).
  EXPECT_LE(with.id_switches, 2) << with.Summary();
  EXPECT_GT(with.idf1, 0.95) << with.Summary();
  EXPECT_LE(with.id_switches, without.id_switches) << without.Summary();
}

TEST(ByteTracker, OptionsAreChecked) {
  TrackerOptions o;
  o.low_score = 0.9;
  o.high_score = 0.5;
  EXPECT_THROW(ByteTracker(o, nullptr), fv::Error);
  o = {};
  o.sot = "tld";
  EXPECT_THAT([&] { ByteTracker t(o, nullptr); }, ThrowsMessage<fv::Error>(HasSubstr("sot")));
}

TEST(ByteTrackerStages, SortDetectionsSplitsByScoreAndMarksOverlaps) {
  TrackerOptions o;  // high 0.5, low 0.2
  const std::vector<Detection> dets = {{cv::Rect2d(0, 0, 20, 40), 0.9},
                                       {cv::Rect2d(5, 0, 20, 40), 0.3},
                                       {cv::Rect2d(100, 0, 20, 40), 0.1},
                                       {cv::Rect2d(200, 0, 20, 40), 0.7}};
  const FrameDetections fd = SortDetections(dets, cv::Mat(), o, nullptr);
  EXPECT_EQ(fd.high, (std::vector<int>{0, 3}));
  EXPECT_EQ(fd.low, (std::vector<int>{1}));
  EXPECT_FALSE(fd.clear[0]);  // the low-score box 1 covers most of it
  EXPECT_TRUE(fd.clear[3]);
  EXPECT_FALSE(fd.field_m[0].has_value());  // no camera
  EXPECT_TRUE(fd.hist[0].empty());          // no frame
  EXPECT_EQ(fd.used, (std::vector<char>(4, 0)));
}

TEST(ByteTrackerStages, PairCostGatesByIouAndReachGrowsWhileLost) {
  TrackerOptions o;
  ByteTracker::Track t;
  t.Init(cv::Rect2d(0, 0, 20, 40));
  const std::vector<Detection> dets = {{cv::Rect2d(0, 0, 20, 40), 0.9},
                                       {cv::Rect2d(2, 0, 20, 40), 0.9},
                                       {cv::Rect2d(100, 0, 20, 40), 0.9}};
  const FrameDetections fd = SortDetections(dets, cv::Mat(), o, nullptr);
  EXPECT_NEAR(PairCost(t, dets, fd, 0, o.match_iou, true, o), 0.0, 1e-12);
  EXPECT_NEAR(PairCost(t, dets, fd, 1, o.match_iou, false, o), 1.0 - Iou(t.box, dets[1].box),
              1e-12);
  EXPECT_GE(PairCost(t, dets, fd, 2, o.match_iou, true, o), 1e9);
  // Re-finding in pixels: reid_speed_px per frame lost plus the box height.
  t.lost_frames = 2;
  const Detection near{cv::Rect2d(60, 0, 20, 40), 0.9}, far{cv::Rect2d(70, 0, 20, 40), 0.9};
  EXPECT_TRUE(InReidReach(t, near, std::nullopt, o));  // 60 <= 2 * 12 + 40
  EXPECT_FALSE(InReidReach(t, far, std::nullopt, o));
  t.lost_frames = 3;
  EXPECT_TRUE(InReidReach(t, far, std::nullopt, o));
  // On the field: 3 m/s at 25 frames/s plus 1 m.
  t.field_m = Eigen::Vector2d(0, 0);
  EXPECT_TRUE(InReidReach(t, far, Eigen::Vector2d(1.3, 0), o));
  EXPECT_FALSE(InReidReach(t, far, Eigen::Vector2d(1.4, 0), o));
}

TEST(ByteTrackerStages, LeftImageUsesTheFootPoint) {
  ByteTracker::Track t;
  t.Init(cv::Rect2d(100, 100, 20, 40));
  EXPECT_FALSE(LeftImage(t, cv::Size(640, 480)));
  t.Init(cv::Rect2d(630, 100, 20, 40));  // foot at x = 640
  EXPECT_TRUE(LeftImage(t, cv::Size(640, 480)));
  t.Init(cv::Rect2d(100, 445, 20, 40));  // foot 5 px below, within a quarter of the height
  EXPECT_FALSE(LeftImage(t, cv::Size(640, 480)));
  t.Init(cv::Rect2d(100, 455, 20, 40));
  EXPECT_TRUE(LeftImage(t, cv::Size(640, 480)));
}

}  // namespace
}  // namespace fv::track
