#include "fieldvision/track/bytetrack.h"

#include <map>
#include <set>

#include <gtest/gtest.h>

#include "fieldvision/track/mot.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::track {
namespace {

struct Walker {
  double x, y, vx, vy;
};

// People crossing each other: detections with noise, misses and low scores while occluded, plus
// clutter; the tracker must keep one id per person.
TEST(ByteTracker, KeepsIdsThroughCrossingsAndMisses) {
  const uint64_t seed = fv::testing::TestSeed(11);
  FV_SEED_TRACE(seed);
  Rng rng(seed);
  std::vector<Walker> people;
  for (int i = 0; i < 6; ++i) {
    // Pairs walk towards each other on nearby rows and cross in the middle.
    const double y = 100 + 60 * (i / 2) + rng.Uniform(-5, 5);
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

TEST(ByteTracker, OptionsAreChecked) {
  TrackerOptions o;
  o.low_score = 0.9;
  o.high_score = 0.5;
  EXPECT_THROW(ByteTracker(o, nullptr), fv::Error);
  o = {};
  o.sot = "tld";
  try {
    ByteTracker t(o, nullptr);
    FAIL();
  } catch (const fv::Error& e) {
    EXPECT_NE(std::string(e.what()).find("sot"), std::string::npos);
  }
}

}  // namespace
}  // namespace fv::track
