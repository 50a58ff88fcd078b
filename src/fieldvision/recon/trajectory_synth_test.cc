// Flights of the synthetic world's "kick" preset (gravity, quadratic drag, bounces; synth.h),
// sampled at its frame rate from the exact centres plus 5 mm noise.
#if __has_include("fieldvision/synth/ball_physics.h")

#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "fieldvision/recon/test_tracks.h"
#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/trajectory_predict.h"
#include "fieldvision/synth/ball_physics.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::recon {
namespace {

TEST(TrajectorySynth, KickPresetFlightsFromTruthWith5mmNoise) {
  const uint64_t seed0 = testing::TestSeed(1);
  double worst_origin = 0, worst_landing = 0, worst_pred = 0;
  int flights_checked = 0;
  for (uint64_t k = 0; k < 3; ++k) {
    const uint64_t seed = seed0 + k;
    FV_SEED_TRACE(seed);
    const synth::SceneSpec spec = synth::Preset("kick", seed);
    const synth::BallTrajectory traj(spec.ball, spec.duration_s());
    util::Rng rng(seed + 1000);
    const std::vector<BallSample> track =
        test_util::NoisyTrack(traj, spec.num_frames, spec.fps, 0.005, rng);
    TrajectoryOptions o;
    o.ball_radius_m = spec.ball.radius_m();
    o.gravity_mps2 = spec.ball.physics.gravity_mps2;
    const TrajectoryResult r = AnalyzeTrajectory(track, o);
    SCOPED_TRACE(r.Summary());
    const double t_end = spec.duration_s() - 1 / spec.fps;
    for (const auto& t : traj.flights()) {
      if (t.t_end_s - t.t_start_s < 0.25 || t.t_end_s > t_end) continue;
      const Flight* best = nullptr;
      for (const auto& f : r.flights) {
        if (std::abs(f.t_start_s - t.t_start_s) < 0.05) best = &f;
      }
      ASSERT_NE(best, nullptr) << "flight " << t.t_start_s << ".." << t.t_end_s << " not found";
      const double eo = (best->origin_m - t.origin).norm();
      const double el = (best->landing_m - t.landing).norm();
      EXPECT_LT(eo, 0.02) << "origin of the flight at " << t.t_start_s;
      EXPECT_LT(el, 0.02) << "landing of the flight at " << t.t_start_s;
      EXPECT_NEAR(best->t_end_s, t.t_end_s, 0.01);
      const LandingPrediction p = PredictFlightLanding(track, r, *best, 0.5, o);
      ASSERT_TRUE(p.ok);
      const double ep = (p.landing_m.head<2>() - t.landing.head<2>()).norm();
      EXPECT_LT(ep, 0.25) << "prediction for the flight at " << t.t_start_s;
      worst_origin = std::max(worst_origin, eo);
      worst_landing = std::max(worst_landing, el);
      worst_pred = std::max(worst_pred, ep);
      ++flights_checked;
    }
  }
  EXPECT_GE(flights_checked, 3);
  RecordProperty("worst_origin_m", std::to_string(worst_origin));
  RecordProperty("worst_landing_m", std::to_string(worst_landing));
  RecordProperty("worst_prediction_m", std::to_string(worst_pred));
  std::cout << "synth kick: " << flights_checked << " flights, worst origin " << worst_origin
            << " m, landing " << worst_landing << " m, prediction " << worst_pred << " m\n";
}

}  // namespace
}  // namespace fv::recon

#endif
