// Live flights: the kick scene's true track (5 mm noise) fed one position at a time gives the
// flights the offline analysis of the whole track gives, each once, in time order; a gap ends
// the track and closes its flights.
#include "fieldvision/pipeline/live_flights.h"

#include <cmath>

#include <gtest/gtest.h>

#include "fieldvision/recon/test_tracks.h"
#include "fieldvision/synth/ball_physics.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::pipeline {
namespace {

std::vector<recon::BallSample> KickTrack(uint64_t seed, recon::TrajectoryOptions* options) {
  const synth::SceneSpec spec = synth::Preset("kick", seed);
  const synth::BallTrajectory trajectory(spec.ball, spec.duration_s());
  util::Rng rng(seed + 1000);
  std::vector<recon::BallSample> track =
      recon::test_util::NoisyTrack(trajectory, spec.num_frames, spec.fps, 0.005, rng, 4);
  options->ball_radius_m = spec.ball.radius_m();
  options->gravity_mps2 = spec.ball.physics.gravity_mps2;
  return track;
}

TEST(LiveFlights, SameFlightsAsTheWholeTrackEachOnce) {
  const uint64_t seed = testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  LiveFlightsOptions o;
  const std::vector<recon::BallSample> track = KickTrack(seed, &o.analysis);
  ASSERT_GT(track.size(), 60u);
  const recon::TrajectoryResult offline = recon::AnalyzeTrajectory(track, o.analysis);
  ASSERT_GE(offline.flights.size(), 2u) << offline.Summary();

  LiveFlights live(o);
  std::vector<recon::Flight> flights;
  size_t closed_before_end = 0;
  for (const recon::BallSample& s : track) {
    for (recon::Flight& f : live.Add(s)) flights.push_back(std::move(f));
  }
  closed_before_end = flights.size();
  for (recon::Flight& f : live.Finish()) flights.push_back(std::move(f));
  // All but the last one or two (too few samples after them) close before the end.
  EXPECT_GE(closed_before_end + 2, offline.flights.size()) << "flights closed only at the end";
  EXPECT_GE(closed_before_end, 1u);
  EXPECT_LT(live.analyses(), static_cast<long long>(track.size()));
  ASSERT_EQ(flights.size(), offline.flights.size()) << offline.Summary();
  for (size_t i = 0; i < flights.size(); ++i) {
    SCOPED_TRACE(i);
    if (i > 0) EXPECT_GE(flights[i].t_start_s, flights[i - 1].t_end_s - 0.01);
    EXPECT_NEAR(flights[i].t_start_s, offline.flights[i].t_start_s, 0.01);
    EXPECT_NEAR(flights[i].t_end_s, offline.flights[i].t_end_s, 0.01);
    EXPECT_LT((flights[i].landing_m - offline.flights[i].landing_m).norm(), 0.03);
  }
}

TEST(LiveFlights, AGapClosesTheTrackAndBadOptionsAreNamed) {
  const uint64_t seed = testing::TestSeed(2);
  FV_SEED_TRACE(seed);
  LiveFlightsOptions o;
  const std::vector<recon::BallSample> track = KickTrack(seed, &o.analysis);
  LiveFlights live(o);
  size_t n = 0;
  for (const recon::BallSample& s : track) n += live.Add(s).size();
  // The same track again a second later: the first one's open flights close with its first
  // position.
  recon::BallSample later = track.front();
  later.time_s = track.back().time_s + 1.0;
  const std::vector<recon::Flight> closed = live.Add(later);
  EXPECT_FALSE(closed.empty());
  for (const recon::Flight& f : closed) EXPECT_LE(f.t_end_s, track.back().time_s + 0.2);
  EXPECT_TRUE(live.Finish().empty());  // one position: no flight
  o.track_gap_s = 0;
  EXPECT_THROW(LiveFlights live2(o), Error);
}

}  // namespace
}  // namespace fv::pipeline
