// Live synchronisation: pairing by capture time, a dead camera never stalls the others, late,
// duplicate and out-of-order messages are dropped and counted, a restarted camera re-admitted.
#include "fieldvision/pipeline/live_sync.h"

#include <gtest/gtest.h>

#include "fieldvision/pipeline/test_messages.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::pipeline {
namespace {

using test_util::Msg;

TEST(LiveSync, PairsByTimeWithJitterAndOffsetsInFrameNumbers) {
  testing::SeededRng rng(2);
  LiveSyncOptions o;
  o.tolerance_s = 0.008;
  LiveSynchronizer sync(3, o);
  // Camera c numbers its frames from 10 c; capture jitter up to 2 ms.
  std::vector<SyncedFrame> groups;
  for (int k = 0; k < 50; ++k) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_TRUE(sync.Add(Msg(c, 10 * c + k, 100 + k / 60.0 + rng.Uniform(-0.002, 0.002)), k));
    }
    while (auto g = sync.Next(k)) groups.push_back(*g);
  }
  while (auto g = sync.Next(100, true)) groups.push_back(*g);
  ASSERT_EQ(groups.size(), 50u);
  for (size_t k = 0; k < groups.size(); ++k) {
    ASSERT_EQ(groups[k].present(), 3);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(groups[k].cameras[c]->frame, 10LL * c + static_cast<long long>(k));
    }
  }
  EXPECT_EQ(sync.complete_groups(), 50);
}

TEST(LiveSync, ADeadCameraDoesNotStallTheOthersAndItsLateFramesAreDropped) {
  LiveSyncOptions o;
  o.max_wait_s = 0.1;
  LiveSynchronizer sync(2, o);
  ASSERT_TRUE(sync.Add(Msg(0, 0, 10.0), 1.0));
  ASSERT_TRUE(sync.Add(Msg(1, 0, 10.0), 1.0));
  ASSERT_TRUE(sync.Next(1.0));  // both: decided at once
  // Camera 1 goes quiet: camera 0's frame waits at most max_wait_s.
  ASSERT_TRUE(sync.Add(Msg(0, 1, 10.1), 1.02));
  EXPECT_FALSE(sync.Next(1.05));
  const auto g = sync.Next(1.13);
  ASSERT_TRUE(g);
  EXPECT_EQ(g->present(), 1);
  // Camera 1's frame of that moment arrives now: late, dropped, counted.
  EXPECT_FALSE(sync.Add(Msg(1, 1, 10.1), 1.2));
  EXPECT_EQ(sync.stats()[1].late, 1);
  // A silent camera is not waited for at all.
  ASSERT_TRUE(sync.Add(Msg(0, 2, 10.2), 1.5));
  EXPECT_TRUE(sync.Next(1.5));
  // Duplicates and out-of-order frames.
  EXPECT_FALSE(sync.Add(Msg(0, 2, 10.2), 1.6));
  EXPECT_FALSE(sync.Add(Msg(0, 1, 10.15), 1.6));
  EXPECT_EQ(sync.stats()[0].duplicates, 1);
  EXPECT_EQ(sync.stats()[0].out_of_order, 1);
  // A restarted camera numbers from 0 again and is paired again.
  sync.Restart(1);
  ASSERT_TRUE(sync.Add(Msg(1, 0, 10.3), 2.0));
  ASSERT_TRUE(sync.Add(Msg(0, 3, 10.3), 2.0));
  const auto again = sync.Next(2.0);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->present(), 2);
  EXPECT_EQ(sync.stats()[1].restarts, 1);
  EXPECT_FALSE(sync.Problems({"a", "b"}).empty());
}

// One frame stamped an hour ahead (a node's clock glitch) is dropped and counted; the streams go
// on pairing. A camera that stays in a new time base is followed there.
TEST(LiveSync, AFrameStampedFarFromItsStreamDoesNotStallFusion) {
  LiveSyncOptions o;
  o.max_time_jump_s = 10;
  LiveSynchronizer sync(2, o);
  ASSERT_TRUE(sync.Add(Msg(0, 0, 1.0), 1.0));
  EXPECT_FALSE(sync.Add(Msg(1, 0, 3600.0), 1.0));  // its first frame, an hour past camera 0's
  ASSERT_TRUE(sync.Add(Msg(1, 1, 1.0), 1.0));
  std::vector<SyncedFrame> groups;
  for (int k = 1; k < 30; ++k) {
    const double t = 1.0 + k / 30.0, arrival = t;
    ASSERT_TRUE(sync.Add(Msg(0, k, t), arrival));
    if (k == 10) EXPECT_FALSE(sync.Add(Msg(1, 100, 7200.0), arrival));  // mid-stream
    ASSERT_TRUE(sync.Add(Msg(1, k + 1, t), arrival));
    while (auto g = sync.Next(arrival)) groups.push_back(*g);
  }
  while (auto g = sync.Next(100, true)) groups.push_back(*g);
  ASSERT_EQ(groups.size(), 30u);
  for (const SyncedFrame& g : groups) EXPECT_EQ(g.present(), 2);
  EXPECT_EQ(sync.stats()[1].implausible, 2);
  EXPECT_EQ(sync.stats()[1].late, 0);
  EXPECT_EQ(sync.stats()[0].late, 0);
  EXPECT_FALSE(sync.Problems({"a", "b"}).empty());
  // The clock both cameras stamp with is stepped back for good: after three frames there each
  // camera is followed, and the groups pair again.
  for (int k = 0; k < 6; ++k) {
    const double t = -100 + k / 30.0, arrival = 3.0 + k / 30.0;
    sync.Add(Msg(1, 200 + k, t), arrival);
    sync.Add(Msg(0, 200 + k, t), arrival);
    while (auto g = sync.Next(arrival)) groups.push_back(*g);
  }
  while (auto g = sync.Next(100, true)) groups.push_back(*g);
  ASSERT_EQ(groups.size(), 34u);
  EXPECT_EQ(groups.back().present(), 2);
  EXPECT_EQ(groups.back().cameras[0]->frame, 205);
}

// Legitimate streams the implausible-time rule must not touch: a camera whose source skipped over
// 10 s (it said so), and one camera alone in another time base is followed without reopening the
// groups the others decided.
TEST(LiveSync, SkipsAndOneCameraInAnotherTimeBaseAreNotTakenForBadTimes) {
  LiveSyncOptions o;
  o.max_time_jump_s = 10;
  LiveSynchronizer sync(2, o);
  ASSERT_TRUE(sync.Add(Msg(0, 0, 1.0), 1.0));
  ASSERT_TRUE(sync.Add(Msg(1, 0, 1.0), 1.0));
  ASSERT_TRUE(sync.Next(1.0));
  sync.SkipUntil(0, 30.0, 2.0);  // both sources dropped 29 s (a stalled network)
  sync.SkipUntil(1, 30.0, 2.0);
  ASSERT_TRUE(sync.Add(Msg(0, 1, 30.0), 2.0));
  EXPECT_TRUE(sync.Add(Msg(1, 870, 30.0), 2.0));
  EXPECT_EQ(sync.stats()[0].implausible + sync.stats()[1].implausible, 0);
  const auto both = sync.Next(2.0);
  ASSERT_TRUE(both);
  EXPECT_EQ(both->present(), 2);
  // Camera 1 alone restarts its clock at 0 (camera 0 goes on at 30 s): after three frames it is
  // followed, but the time camera 0 decided stays decided (no group back in time).
  double latest_group_s = both->time_s;
  for (int k = 0; k < 6; ++k) {
    sync.Add(Msg(1, 1000 + k, 0.1 + k / 30.0), 3.0 + k / 30.0);
    sync.Add(Msg(0, 2 + k, 30.1 + k / 30.0), 3.0 + k / 30.0);
    while (auto g = sync.Next(3.0 + k / 30.0)) {
      EXPECT_GE(g->time_s, latest_group_s);
      latest_group_s = g->time_s;
    }
  }
  EXPECT_EQ(sync.stats()[1].implausible, 2);
}

// One camera's clock jumps forward for good (its node's clock stepped): it is followed there
// after three frames, but its frames do not decide that time for the others, whose frames go on
// pairing with each other (before, every frame of theirs was late from then on).
TEST(LiveSync, OneCameraJumpingAheadDoesNotMakeTheOthersLate) {
  LiveSyncOptions o;
  o.max_time_jump_s = 10;
  o.max_wait_s = 0.1;
  LiveSynchronizer sync(3, o);
  std::vector<SyncedFrame> groups;
  for (int k = 0; k < 90; ++k) {
    const double t = k / 60.0, arrival = 1.0 + k / 60.0;
    for (int c = 0; c < 3; ++c) sync.Add(Msg(c, k, c == 0 && k >= 40 ? t + 1000 : t), arrival);
    while (auto g = sync.Next(arrival)) groups.push_back(*g);
  }
  while (auto g = sync.Next(100, true)) groups.push_back(*g);
  EXPECT_EQ(sync.stats()[1].late, 0);
  EXPECT_EQ(sync.stats()[2].late, 0);
  int paired_after_jump = 0;
  for (const SyncedFrame& g : groups) {
    if (g.cameras[1] && g.cameras[1]->frame >= 40) paired_after_jump += g.cameras[2] ? 1 : 0;
  }
  EXPECT_EQ(paired_after_jump, 50);

  // A glitch of three frames it comes back from: the frame held from the far time base is
  // dropped when camera 0 is followed back, and camera 0 pairs again.
  LiveSynchronizer glitch(3, o);
  groups.clear();
  for (int k = 0; k < 90; ++k) {
    const double t = k / 60.0, arrival = 1.0 + k / 60.0;
    const bool off = k >= 40 && k < 43;
    for (int c = 0; c < 3; ++c) glitch.Add(Msg(c, k, c == 0 && off ? t + 1000 : t), arrival);
    while (auto g = glitch.Next(arrival)) groups.push_back(*g);
  }
  while (auto g = glitch.Next(100, true)) groups.push_back(*g);
  for (size_t i = 1; i < groups.size(); ++i) EXPECT_GE(groups[i].time_s, groups[i - 1].time_s);
  EXPECT_EQ(groups.back().present(), 3);
  EXPECT_EQ(glitch.stats()[0].unpaired, 0);
  EXPECT_EQ(glitch.stats()[0].implausible, 5);  // 40, 41, then 42 held; 43, 44

  // What holds a camera gone ahead is another camera still delivering frames that count: not one
  // whose source is stuck while its node answers clock pings, nor one whose clock stepped back
  // (its frames all late). Either stopped all fusion for good.
  for (const bool stuck : {true, false}) {
    SCOPED_TRACE(stuck ? "camera 0 stuck, pinging" : "camera 0's clock stepped back");
    LiveSynchronizer sync3(3, o);
    long long decided = 0;
    for (int k = 0; k < 30 * 60; ++k) {
      const double t = k / 60.0, arrival = 1.0 + t;
      if (k < 40) {
        sync3.Add(Msg(0, k, t), arrival);
      } else if (stuck) {
        sync3.Admit(0, arrival);  // a clock ping
      } else {
        sync3.Add(Msg(0, k, t - 1000), arrival);
      }
      for (int c = 1; c < 3; ++c) sync3.Add(Msg(c, k, t), arrival);
      while (sync3.Next(arrival)) ++decided;
    }
    EXPECT_GT(decided, 30 * 60 - 10);
  }
}

// Nodes connect one after another: a camera not heard from yet is waited for (up to max_wait_s
// after the first camera was heard), so the first node's frames do not make the others' late.
TEST(LiveSync, ACameraNotHeardFromYetIsWaitedFor) {
  LiveSyncOptions o;
  o.max_wait_s = 5;
  LiveSynchronizer sync(2, o);
  for (int k = 0; k < 30; ++k) ASSERT_TRUE(sync.Add(Msg(0, k, k / 60.0), 1.0 + k * 0.001));
  EXPECT_FALSE(sync.Next(1.5));  // camera 1 may still connect
  for (int k = 0; k < 30; ++k) ASSERT_TRUE(sync.Add(Msg(1, k, k / 60.0), 2.0));
  int both = 0;
  while (auto g = sync.Next(2.0)) both += g->present() == 2;
  EXPECT_EQ(both, 30);
  EXPECT_EQ(sync.stats()[1].late, 0);
  // A camera that never connects delays the first groups by max_wait_s only.
  LiveSynchronizer alone(2, o);
  ASSERT_TRUE(alone.Add(Msg(0, 0, 0.0), 1.0));
  EXPECT_FALSE(alone.Next(5.9));
  EXPECT_TRUE(alone.Next(6.1));
  ASSERT_TRUE(alone.Add(Msg(0, 1, 1 / 60.0), 6.2));
  EXPECT_TRUE(alone.Next(6.2));
}

// Cameras of other rates, or started at other times, number their frames otherwise: a group's
// frame is the fastest camera's (where its count would be when it is missing), and increases
// (the first present camera's gave 9, 19, 10, 21, ... with a 30 fps camera among 60 fps ones).
TEST(LiveSync, GroupsAreNumberedByTheFastestCamera) {
  LiveSyncOptions o;
  LiveSynchronizer sync(2, o);
  sync.SetFrameRate(0, 30);  // as the nodes' hellos say
  sync.SetFrameRate(1, 60);
  std::vector<SyncedFrame> groups;
  for (int k = 0; k < 60; ++k) {
    const double t = k / 60.0, arrival = 1.0 + t;
    if (k % 2 == 0) ASSERT_TRUE(sync.Add(Msg(0, 100 + k / 2, t), arrival));  // 30 fps, from 100
    if (k != 31) ASSERT_TRUE(sync.Add(Msg(1, k, t), arrival));               // 60 fps, one lost
    while (auto g = sync.Next(arrival)) groups.push_back(*g);
  }
  while (auto g = sync.Next(100, true)) groups.push_back(*g);
  ASSERT_GE(groups.size(), 58u);
  for (size_t i = 1; i < groups.size(); ++i) {
    EXPECT_GT(groups[i].frame, groups[i - 1].frame) << "group " << i;
  }
  for (const SyncedFrame& g : groups) {
    EXPECT_EQ(g.frame, std::llround(g.time_s * 60)) << g.time_s;  // camera 1's numbers
  }
}

// A camera whose source skipped frames says so (SkipUntil): the others' frames before it are
// paired at once instead of waiting for that camera; frames after it still wait.
TEST(LiveSync, SkippedFramesAreNotWaitedFor) {
  LiveSyncOptions o;
  o.max_wait_s = 10;  // far longer than the test: only SkipUntil can release a group
  LiveSynchronizer sync(2, o);
  const double dt = 1 / 60.0;
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(sync.Add(Msg(0, k, 100 + k * dt), 1.0));
    ASSERT_TRUE(sync.Add(Msg(1, k, 100 + k * dt), 1.0));
  }
  ASSERT_TRUE(sync.Next(1.0));
  ASSERT_TRUE(sync.Next(1.0));
  // Camera 0 sends frames 2..4; camera 1 skipped 2 and 3 and is working on 4.
  for (int k = 2; k < 5; ++k) ASSERT_TRUE(sync.Add(Msg(0, k, 100 + k * dt), 1.0));
  EXPECT_FALSE(sync.Next(1.0));  // waits for camera 1's frame 2
  sync.SkipUntil(1, 100 + 4 * dt, 1.0);
  for (int k = 2; k < 4; ++k) {
    const auto g = sync.Next(1.0);
    ASSERT_TRUE(g) << "frame " << k;
    EXPECT_EQ(g->frame, k);
    EXPECT_EQ(g->present(), 1);
  }
  EXPECT_FALSE(sync.Next(1.0));  // frame 4 waits for camera 1
  ASSERT_TRUE(sync.Add(Msg(1, 4, 100 + 4 * dt), 1.0));
  const auto g = sync.Next(1.0);
  ASSERT_TRUE(g);
  EXPECT_EQ(g->present(), 2);
  EXPECT_EQ(sync.stats()[1].late, 0);
}

}  // namespace
}  // namespace fv::pipeline
