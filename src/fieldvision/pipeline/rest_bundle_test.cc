// Resting runs: found where a noisy track stands still and not where it rolls or where flights
// took the rows; a still ball's rows all take one point triangulated on every frame's candidates,
// nearer the truth than the frames' own positions, without a candidate far off.
#include "fieldvision/pipeline/rest_bundle.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/pipeline/test_messages.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::pipeline {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

using test_util::CornerRig;

recon::BallSample Sample(long long frame, const Eigen::Vector3d& p) {
  recon::BallSample s;
  s.frame = frame;
  s.time_s = frame / 60.0;
  s.ball_in_world = p;
  s.n_cams = 4;
  return s;
}

// Rows in runs, per row (1: in a run).
std::vector<int> InRuns(size_t rows, const std::vector<RestRun>& runs) {
  std::vector<int> in(rows, 0);
  for (const RestRun& r : runs) {
    for (size_t i = r.first; i <= r.last; ++i) in[i] = 1;
  }
  return in;
}

TEST(RestingRuns, StillPartsOfANoisyTrackAreRunsRollingOnesAreNot) {
  const uint64_t seed = fv::testing::TestSeed(3);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const auto noise = [&] {
    return Eigen::Vector3d(rng.Normal(0, 0.005), rng.Normal(0, 0.005), rng.Normal(0, 0.003));
  };
  std::vector<recon::BallSample> track;
  track.reserve(120);
  const Eigen::Vector3d a(-2, 1, 0.11), b(1, 2.5, 0.11);
  for (int i = 0; i < 40; ++i) track.push_back(Sample(i, a + noise()));  // still
  for (int i = 0; i < 40; ++i) {  // rolling from a towards b at 0.5 m/s
    const Eigen::Vector3d p = a + (b - a).normalized() * (0.5 * (i + 1) / 60.0);
    track.push_back(Sample(40 + i, p + noise()));
  }
  for (int i = 0; i < 40; ++i) track.push_back(Sample(80 + i, b + noise()));  // still again
  const RestBundleOptions o;
  const std::vector<RestRun> runs = FindRestingRuns(track, {}, o);
  const std::vector<int> in = InRuns(track.size(), runs);
  int still_in = 0, rolling_in = 0;
  for (size_t i = 0; i < track.size(); ++i) {
    const bool rolling = i >= 40 && i < 80;
    (rolling ? rolling_in : still_in) += in[i];
    // Of the roll, at most its first few steps (within the noise of where it started).
    if (rolling) EXPECT_TRUE(!in[i] || i < 44) << "row " << i;
  }
  EXPECT_GE(still_in, 64) << "of 80 still rows";
  for (const RestRun& r : runs) {
    EXPECT_GE(static_cast<int>(r.last - r.first + 1), o.min_frames);
    EXPECT_TRUE(r.last < 44 || r.first >= 80) << r.first << ".." << r.last;
  }
  // Rows a flight took belong to no run; a gap in time ends one.
  std::vector<char> skip(track.size(), 0);
  for (int i = 5; i < 40; ++i) skip[i] = 1;
  for (const RestRun& r : FindRestingRuns(track, skip, o)) EXPECT_GE(r.first, 40u);
  std::vector<recon::BallSample> gap = track;
  for (size_t i = 20; i < gap.size(); ++i) gap[i].time_s += 1.0;
  for (const RestRun& r : FindRestingRuns(gap, {}, o)) {
    EXPECT_TRUE(r.last < 20 || r.first >= 20) << r.first << ".." << r.last;
  }
  // A slow roll (5 cm/s for 1 s, 5 cm in all) is cut into pieces that move less than about
  // max_drift_m each.
  std::vector<recon::BallSample> slow;
  slow.reserve(60);
  for (int i = 0; i < 60; ++i) {
    slow.push_back(Sample(i, a + Eigen::Vector3d(0.05 * i / 60.0, 0, 0) + 0.2 * noise()));
  }
  for (const RestRun& r : FindRestingRuns(slow, {}, o)) {
    EXPECT_LE((slow[r.last].ball_in_world - slow[r.first].ball_in_world).norm(), 0.015)
        << r.first << ".." << r.last;
  }
  RestBundleOptions bad;
  bad.min_frames = 1;  // below 2
  EXPECT_THAT([&] { FindRestingRuns(track, {}, bad); },
              ThrowsMessage<Error>(HasSubstr("min_frames")));
  bad = {};
  bad.max_frames_per_camera = 0;
  EXPECT_THAT([&] { FindRestingRuns(track, {}, bad); },
              ThrowsMessage<Error>(HasSubstr("max_frames_per_camera")));
  EXPECT_THAT([&] { FindRestingRuns(track, std::vector<char>(3, 0), o); },
              ThrowsMessage<Error>(HasSubstr("skip flags")));
}

TEST(BundleRests, AStillBallTakesOnePointFromAllFramesCandidates) {
  const uint64_t seed = fv::testing::TestSeed(5);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const std::vector<camera::Camera> cams = CornerRig();
  const Eigen::Vector3d ball(1.5, -0.5, 0.11);
  std::vector<std::vector<CameraMessage>> messages(cams.size());
  std::vector<recon::BallSample> track;
  double frames_err_m = 0.0;
  for (int f = 0; f < 30; ++f) {
    std::vector<recon::View> views;
    for (size_t c = 0; c < cams.size(); ++c) {
      CameraMessage m;
      m.camera = static_cast<int>(c);
      m.frame = f;
      m.time_s = f / 60.0;
      recon::BallObservation o;
      o.centre_px =
          *cams[c].Project(ball) + Eigen::Vector2d(rng.Normal(0, 0.4), rng.Normal(0, 0.4));
      o.sigma_px = 0.4;
      m.candidates.push_back(o);
      views.push_back({static_cast<int>(c), o});
      messages[c].push_back(m);
    }
    const recon::TriangulationResult r = recon::TriangulatePoint(cams, views);
    ASSERT_TRUE(r.ok());
    track.push_back(Sample(f, r.point_world));
    frames_err_m += (r.point_world - ball).norm() / 30.0;
  }
  // Then the ball rolls away: those rows keep their positions.
  for (int f = 30; f < 40; ++f) {
    track.push_back(Sample(f, ball + Eigen::Vector3d(0.1 * (f - 29), 0, 0)));
  }
  const std::vector<recon::BallSample> before = track;
  const RestBundle b = BundleRests(cams, messages, 0.11, 0.5 / 60.0, {}, {}, &track);
  ASSERT_GE(b.runs, 1);
  EXPECT_GE(b.rows, 24);
  EXPECT_LT(b.rms_px, 0.7);
  double refined_err_m = 0;
  int refined = 0;
  for (int f = 0; f < 30; ++f) {
    if (track[f].ball_in_world == before[f].ball_in_world) continue;
    refined_err_m += (track[f].ball_in_world - ball).norm();
    ++refined;
  }
  EXPECT_EQ(refined, b.rows);
  EXPECT_LT(refined_err_m / refined, 0.5 * frames_err_m)
      << "frames' mean error " << frames_err_m * 1e3 << " mm";
  for (int f = 30; f < 40; ++f) EXPECT_EQ(track[f].ball_in_world, before[f].ball_in_world) << f;
  // A long rest is triangulated on at most max_frames_per_camera frames a camera.
  RestBundleOptions few;
  few.max_frames_per_camera = 7;
  std::vector<recon::BallSample> capped = before;
  const RestBundle c = BundleRests(cams, messages, 0.11, 0.5 / 60.0, {}, few, &capped);
  ASSERT_GE(c.runs, 1);
  EXPECT_LE(c.observations, 4 * 7 * c.runs);
  EXPECT_GE(c.observations, 4 * 5);
  // With one camera's candidates only there is nothing to refine on.
  std::vector<std::vector<CameraMessage>> one(cams.size());
  one[0] = messages[0];
  std::vector<recon::BallSample> same = before;
  const RestBundle none = BundleRests(cams, one, 0.11, 0.5 / 60.0, {}, {}, &same);
  EXPECT_EQ(none.runs, 0);
  EXPECT_EQ(same[3].ball_in_world, before[3].ball_in_world);
  // What `ball` prints: one line per kind of views, nothing without a run.
  EXPECT_EQ(none.Summary("the views"), "");
  const RestBundle one_run{1, 24, 96, 0.183};
  EXPECT_EQ(one_run.Summary("the views"),
            "1 resting ball refined on the views (24 rows, 0.18 px RMS)");
  const RestBundle two_runs{2, 30, 100, 0.2};
  EXPECT_EQ(two_runs.Summary("x"), "2 resting balls refined on x (30 rows, 0.20 px RMS)");
}

}  // namespace
}  // namespace fv::pipeline
