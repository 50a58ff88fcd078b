// Issue 18: a long track is many kicks in a row; each is found as it is alone (the stages that
// walked the whole track per flight or per block made a 2,000,000-row track run for hours).
#include <gtest/gtest.h>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/trajectory_sim.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::recon {
namespace {

TEST(TrajectoryLong, RepeatedKicksGiveTheFlightsOfOneKickEachTime) {
  testing::SeededRng rng(21);
  BallSimOptions o;
  o.start_m = {-6, -1, 0.11};
  o.kicks = {{0.3, {9, 2, 7}}};
  o.restitution = 0.6;
  o.rolling_decel_mps2 = 3.0;  // at rest before the next kick
  o.duration_s = 4.5;
  const BallSimulation sim(o);
  // 47 frames/s: no gap between samples is exactly one of the analysis' time spans (0.1 s
  // windows, 0.5 s gaps), which the rounding of shifted times would tip either way.
  const double fps = 47.0;
  const auto one = sim.Sample(fps, 0.005, 0.02, 0.01, 0.5, rng);
  ASSERT_GT(one.size(), 100u);
  const Eigen::Vector3d shift = sim.BallAt(o.duration_s) - o.start_m;  // where the next starts
  const double period_s = one.back().time_s + 1 / fps;
  const int copies = 12;
  std::vector<BallSample> track;
  for (int c = 0; c < copies; ++c) {
    for (BallSample s : one) {
      s.time_s += c * period_s;
      s.frame = static_cast<long long>(track.size());
      s.ball_in_world += c * shift;
      track.push_back(s);
    }
  }
  TrajectoryOptions opt;
  opt.noise_m = 0.005;  // estimated from the whole track otherwise: a little different there
  const TrajectoryResult alone = AnalyzeTrajectory(one, opt);
  ASSERT_GE(alone.flights.size(), 2u) << alone.Summary();
  size_t calls = 0, last_done = 0, last_total = 0;
  opt.progress = [&](size_t done, size_t total) {
    EXPECT_GT(done, last_done);
    ++calls;
    last_done = done;
    last_total = total;
  };
  const TrajectoryResult all = AnalyzeTrajectory(track, opt);
  ASSERT_EQ(all.flights.size(), copies * alone.flights.size()) << all.Summary();
  EXPECT_EQ(last_done, last_total);
  EXPECT_EQ(calls, last_total);
  for (int c = 0; c < copies; ++c) {
    for (size_t i = 0; i < alone.flights.size(); ++i) {
      SCOPED_TRACE(::testing::Message() << "copy " << c << " flight " << i);
      const Flight& a = alone.flights[i];
      const Flight& f = all.flights[c * alone.flights.size() + i];
      EXPECT_EQ(f.model_kind(), a.model_kind());
      EXPECT_EQ(f.samples.size(), a.samples.size());
      EXPECT_NEAR(f.t_start_s - c * period_s, a.t_start_s, 1e-6);
      EXPECT_NEAR(f.t_end_s - c * period_s, a.t_end_s, 1e-6);
      EXPECT_LT((f.origin_m - c * shift - a.origin_m).norm(), 1e-6);
      EXPECT_LT((f.landing_m - c * shift - a.landing_m).norm(), 1e-6);
    }
  }
}

}  // namespace
}  // namespace fv::recon
