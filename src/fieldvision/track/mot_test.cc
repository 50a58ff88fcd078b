#include "fieldvision/track/mot.h"

#include <fstream>

#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::track {
namespace {

// Random walkers: `people` tracks over `frames` frames.
std::vector<TrackRow> Walkers(Rng& rng, int people, int frames) {
  std::vector<TrackRow> rows;
  for (int p = 0; p < people; ++p) {
    double x = rng.Uniform(0, 600), y = rng.Uniform(0, 400);
    const double vx = rng.Uniform(-3, 3), vy = rng.Uniform(-2, 2);
    for (int f = 0; f < frames; ++f) {
      rows.push_back({f, p + 1, cv::Rect2d(x + vx * f, y + vy * f, 30, 80), 1.0, {}, {}});
    }
  }
  return rows;
}

TEST(Mot, PerfectTracksScoreOne) {
  const uint64_t seed = fv::testing::TestSeed(3);
  FV_SEED_TRACE(seed);
  Rng rng(seed);
  const auto gt = Walkers(rng, 5, 50);
  auto est = gt;
  for (auto& r : est) r.id += 100;  // ids need not be equal
  const MotMetrics m = EvaluateMot(gt, est);
  EXPECT_DOUBLE_EQ(m.mota, 1.0);
  EXPECT_DOUBLE_EQ(m.idf1, 1.0);
  EXPECT_NEAR(m.hota, 1.0, 1e-9);
  EXPECT_NEAR(m.motp, 1.0, 1e-9);
  EXPECT_EQ(m.id_switches, 0);
  EXPECT_EQ(m.tp, 250);
}

TEST(Mot, CountsMissesFalsePositivesAndSwitches) {
  const uint64_t seed = fv::testing::TestSeed(4);
  FV_SEED_TRACE(seed);
  Rng rng(seed);
  const int frames = 40;
  const auto gt = Walkers(rng, 3, frames);
  std::vector<TrackRow> est;
  int dropped = 0;
  for (auto r : gt) {
    if (r.id == 1 && r.frame % 4 == 0) {  // misses of person 1
      ++dropped;
      continue;
    }
    if (r.id == 2 && r.frame >= 20) r.id = 7;  // one id switch for person 2
    est.push_back(r);
  }
  est.push_back({5, 99, cv::Rect2d(-500, -500, 30, 80), 0.5, {}, {}});  // a false positive
  const MotMetrics m = EvaluateMot(gt, est);
  EXPECT_EQ(m.fn, dropped);
  EXPECT_EQ(m.fp, 1);
  EXPECT_EQ(m.id_switches, 1);
  EXPECT_NEAR(m.mota, 1.0 - double(dropped + 1 + 1) / gt.size(), 1e-12);
  // IDF1: person 2 is split in halves, only one half counts.
  const double idtp = (frames - dropped) + frames / 2 + frames;
  EXPECT_NEAR(m.idf1, 2 * idtp / (gt.size() + est.size()), 1e-12);
  EXPECT_LT(m.hota, 1.0);
  EXPECT_GT(m.hota, 0.5);
}

TEST(Mot, ShiftedBoxesBelowIouThresholdDoNotMatch) {
  std::vector<TrackRow> gt = {{0, 1, cv::Rect2d(0, 0, 10, 10), 1, {}, {}}};
  std::vector<TrackRow> est = {{0, 1, cv::Rect2d(6, 0, 10, 10), 1, {}, {}}};  // IoU 4/16
  const MotMetrics m = EvaluateMot(gt, est);
  EXPECT_EQ(m.tp, 0);
  EXPECT_EQ(m.fp, 1);
  EXPECT_EQ(m.fn, 1);
}

TEST(Mot, CsvRoundTripAndBadFile) {
  const std::string dir = fv::testing::TempDir();
  std::vector<TrackRow> rows = {{3, 2, cv::Rect2d(1.5, 2.5, 30, 60), 0.75, 1.25, -2.5},
                                {4, 2, cv::Rect2d(2, 3, 30, 60), 0.5, {}, {}}};
  WriteTracksCsv(rows, dir + "/t.csv");
  const auto back = ReadTracksCsv(dir + "/t.csv");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].frame, 3);
  EXPECT_NEAR(back[0].box.x, 1.5, 1e-9);
  ASSERT_TRUE(back[0].x_m.has_value());
  EXPECT_NEAR(*back[0].y_m, -2.5, 1e-9);
  EXPECT_FALSE(back[1].x_m.has_value());
  EXPECT_THROW(ReadTracksCsv(dir + "/missing.csv"), fv::Error);
  {
    std::ofstream bad(dir + "/bad.csv");
    bad << "frame,id,bb_left,bb_top,bb_width,bb_height\n1,2,abc,4,5,6\n";
  }
  try {
    ReadTracksCsv(dir + "/bad.csv");
    FAIL() << "no error";
  } catch (const fv::Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fv::track
