#include "fieldvision/pipeline/frame_sync.h"

#include <cmath>

#include <gtest/gtest.h>

#include "fieldvision/pipeline/test_messages.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::pipeline {
namespace {

using test_util::Msg;

// Feeds whole streams the way the fusion stage does (pull from the camera that is waited on).
std::vector<SyncedFrame> Feed(FrameSynchronizer& sync,
                              const std::vector<std::vector<CameraMessage>>& streams) {
  std::vector<size_t> next(streams.size(), 0);
  std::vector<SyncedFrame> out;
  while (true) {
    while (auto g = sync.Next()) out.push_back(*g);
    if (sync.Done()) break;
    const int c = sync.Waiting();
    EXPECT_GE(c, 0);
    if (c < 0) break;
    if (next[c] < streams[c].size()) {
      sync.Add(streams[c][next[c]++]);
    } else {
      sync.EndOfStream(c);
    }
  }
  return out;
}

TEST(SyncedFrame, FrameOfTheFirstPresentCameraAndMeanTime) {
  SyncedFrame g;
  g.cameras.resize(3);
  g.cameras[1] = Msg(1, 7, 0.25);
  g.cameras[2] = Msg(2, 9, 0.35);
  EXPECT_EQ(g.SetFrameAndTime(), 2);
  EXPECT_EQ(g.frame, 7);
  EXPECT_DOUBLE_EQ(g.time_s, 0.3);
}

TEST(FrameSync, ByIndexWithDropsDuplicatesAndDifferentLengths) {
  std::vector<std::vector<CameraMessage>> s(3);
  for (int f = 0; f < 20; ++f) s[0].push_back(Msg(0, f, f / 60.0));
  for (int f = 0; f < 20; ++f) {
    if (f == 5 || f == 6) continue;  // camera 1 dropped two frames
    s[1].push_back(Msg(1, f, f / 60.0));
    if (f == 9) s[1].push_back(Msg(1, f, f / 60.0));  // and duplicated one
  }
  for (int f = 0; f < 12; ++f) s[2].push_back(Msg(2, f, f / 60.0));  // a shorter video
  FrameSynchronizer sync(3, {});
  const auto frames = Feed(sync, s);
  ASSERT_EQ(frames.size(), 20u);
  for (size_t i = 0; i < frames.size(); ++i) {
    const SyncedFrame& g = frames[i];
    EXPECT_EQ(g.frame, static_cast<long long>(i));
    for (const auto& m : g.cameras) {
      if (m) EXPECT_EQ(m->frame, g.frame);  // never paired across frames
    }
    EXPECT_EQ(g.cameras[1].has_value(), i != 5 && i != 6);
    EXPECT_EQ(g.cameras[2].has_value(), i < 12);
  }
  const SyncReport& r = sync.report();
  EXPECT_EQ(r.cameras[1].gaps, 2);
  EXPECT_EQ(r.cameras[1].duplicates, 1);
  EXPECT_EQ(r.cameras[2].last_frame, 11);
  EXPECT_EQ(r.complete_groups, 10);
  const auto problems = r.Problems();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].rfind("camera 1: ", 0), 0u) << problems[0];
  EXPECT_NE(problems[0].find("2 frames missing (dropped)"), std::string::npos);
  EXPECT_NE(problems[0].find("1 duplicated"), std::string::npos);
  EXPECT_NE(problems[1].find("ended at frame 11"), std::string::npos);
  // Named cameras; in detection files a frame without a row had no detection.
  SyncReport detections = r;
  detections.gaps_are_drops = false;
  const auto named = detections.Problems({"left", "right", "top"});
  ASSERT_EQ(named.size(), 2u);
  EXPECT_EQ(named[0].rfind("right: 2 frames without a detection", 0), 0u) << named[0];
  EXPECT_EQ(named[1].rfind("top: ", 0), 0u) << named[1];
}

TEST(FrameSync, UnsynchronizedCamerasArePairedByTimeOnly) {
  testing::SeededRng rng(22);
  // Camera 0 at 60 fps from t = 0; camera 1 at 60 fps started later with a clock offset of a
  // fraction of a frame and jitter; camera 2 at 30 fps (every other moment has no partner).
  const double dt = 1.0 / 60.0, tol = 0.3 * dt;
  std::vector<std::vector<CameraMessage>> s(3);
  for (int f = 0; f < 120; ++f) s[0].push_back(Msg(0, f, f * dt));
  const int late = rng.UniformInt(1, 10);
  const double offset = rng.Uniform(-0.2, 0.2) * dt;
  for (int f = 0; f < 100; ++f) {
    s[1].push_back(Msg(1, f, (f + late) * dt + offset + rng.Uniform(-0.02, 0.02) * dt));
  }
  for (int f = 0; f < 60; ++f) {
    s[2].push_back(Msg(2, f, 2 * f * dt + rng.Uniform(-0.05, 0.05) * dt));
  }
  SyncOptions opt;
  opt.mode = SyncMode::kTimestamp;
  opt.tolerance_s = tol;
  FrameSynchronizer sync(3, opt);
  const auto frames = Feed(sync, s);
  int with0and1 = 0, with2 = 0;
  for (const SyncedFrame& g : frames) {
    double lo = 1e9, hi = -1e9;
    for (const auto& m : g.cameras) {
      if (!m) continue;
      lo = std::min(lo, m->time_s);
      hi = std::max(hi, m->time_s);
    }
    EXPECT_LE(hi - lo, tol + 1e-12);  // never combines different moments
    if (g.cameras[0] && g.cameras[1]) {
      ++with0and1;
      EXPECT_EQ(g.cameras[1]->frame + late, g.cameras[0]->frame);
    }
    if (g.cameras[2]) {
      ++with2;
      if (g.cameras[0]) EXPECT_EQ(g.cameras[0]->frame, 2 * g.cameras[2]->frame);
    }
  }
  EXPECT_EQ(with0and1, 100);
  EXPECT_EQ(with2, 60);
  EXPECT_EQ(frames.size(), 120u);
  // Camera 0's first `late` frames and odd frames beyond camera 1's end have no partner.
  EXPECT_GT(sync.report().cameras[0].unpaired, 0);
}

TEST(FrameSync, BadMessagesAreErrors) {
  FrameSynchronizer sync(2, {});
  EXPECT_THROW(sync.Add(Msg(2, 0, 0)), Error);
  EXPECT_THROW(sync.Add(Msg(0, 0, NAN)), Error);
  sync.EndOfStream(0);
  EXPECT_THROW(sync.Add(Msg(0, 1, 0)), Error);
  SyncOptions bad;
  bad.tolerance_s = 0;
  EXPECT_THROW(FrameSynchronizer(2, bad), Error);
}

}  // namespace
}  // namespace fv::pipeline
