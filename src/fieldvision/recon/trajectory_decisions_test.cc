#include "fieldvision/recon/trajectory_decisions.h"

#include <cmath>

#include <gtest/gtest.h>

#include "fieldvision/recon/trajectory_sim.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::recon {
namespace {

struct Scene {
  std::vector<BallSample> track;
  TrajectoryResult result;
};

Scene RunScene(const BallSimulation& sim, const TrajectoryOptions& to, util::Rng& rng) {
  Scene s;
  s.track = sim.Sample(50.0, 0.005, 0.0, 0.0, 0.0, rng);
  s.result = AnalyzeTrajectory(s.track, to);
  return s;
}

// A flight's landing is told before the next flight's bounce at the same moment (the timeline
// said "flight 1: bounce" before "flight 0: lands").
TEST(TrajectoryDecisions, TheTimelineTellsALandingBeforeTheBounceAfterIt) {
  testing::SeededRng rng(32);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  TrajectoryOptions to;
  BallSimOptions o;
  o.start_m = {-4.0, 0.0, 0.11};
  o.kicks = {{0.1, Eigen::Vector3d(5.0, 1.0, 6.0)}};
  o.duration_s = 2.5;
  const Scene s = RunScene(BallSimulation(o), to, rng);
  ASSERT_GE(s.result.flights.size(), 2u);
  const Decisions d = MakeDecisions(s.track, s.result, &field, to, DecisionOptions());
  int pairs = 0;
  for (size_t i = 1; i < d.timeline.size(); ++i) {
    const TimelineEvent &a = d.timeline[i - 1], &b = d.timeline[i];
    if (a.time_s != b.time_s) continue;
    ++pairs;
    EXPECT_LE(a.flight, b.flight) << a.text << " / " << b.text;
  }
  EXPECT_GE(pairs, 1);
}

TEST(TrajectoryDecisions, GoalLineCrossingBetweenThePostsWithItsTime) {
  testing::SeededRng rng(31);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  ASSERT_FALSE(field.goals.empty());
  const field::FieldGoal* right = nullptr;
  for (const auto& g : field.goals) {
    if (g.side > 0) right = &g;
  }
  ASSERT_NE(right, nullptr);
  TrajectoryOptions to;
  for (const double y_aim : {0.3 * right->y_max_m, right->y_max_m + 0.5}) {
    BallSimOptions o;
    o.start_m = {4.0, 0.0, 0.11};
    // Reaches the goal line in ~0.8 s at 0.5 m height.
    const double T = 0.8, dx = right->line_x_m + 0.5 - 4.0;
    o.kicks = {{0.1, Eigen::Vector3d(dx / T, y_aim / T, (0.4 + 4.905 * T * T) / T)}};
    o.duration_s = 1.6;
    const BallSimulation sim(o);
    const Scene s = RunScene(sim, to, rng);
    const Decisions d = MakeDecisions(s.track, s.result, &field, to, DecisionOptions());
    // Truth: the first time the whole ball is beyond the line, between the posts.
    double t_true = -1;
    for (double t = 0; t < o.duration_s; t += 1e-4) {
      const Eigen::Vector3d p = sim.BallAt(t);
      if (p.x() - right->line_x_m > 0.5 * field.line_width_m + to.ball_radius_m) {
        if (p.y() >= right->y_min_m && p.y() <= right->y_max_m && p.z() <= right->height_m) {
          t_true = t;
        }
        break;
      }
    }
    if (t_true > 0) {
      ASSERT_EQ(d.goals.size(), 1u) << "aim " << y_aim;
      EXPECT_EQ(d.goals[0].goal, right->name);
      EXPECT_NEAR(d.goals[0].time_s, t_true, 0.005);
      bool in_timeline = false;
      for (const auto& e : d.timeline) in_timeline |= e.text.find("GOAL") != std::string::npos;
      EXPECT_TRUE(in_timeline);
    } else {
      EXPECT_TRUE(d.goals.empty()) << "aim " << y_aim << " is wide of the post";
    }
  }
}

// A goal is the ball crossing the line inside the goal mouth: not a ball over the bar that
// comes down behind the line between the posts, nor one that never was in front of the line
// (both were called goals, 1.67 m behind the line).
TEST(TrajectoryDecisions, OverTheBarOrBehindTheLineIsNoGoal) {
  testing::SeededRng rng(37);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const field::FieldGoal* right = nullptr;
  for (const auto& g : field.goals) {
    if (g.side > 0) right = &g;
  }
  ASSERT_NE(right, nullptr);
  TrajectoryOptions to;
  // Over the bar: from 5 m in front, 1.3 m over the bar at the line, landing 2 m behind it.
  BallSimOptions over;
  over.start_m = {right->line_x_m - 5.0, 0.0, 0.11};
  const double T = 1.2, dx = 7.0;
  over.kicks = {{0.05, Eigen::Vector3d(dx / T, 0.0, 4.905 * T)}};
  over.duration_s = 1.6;
  const BallSimulation sim_over(over);
  double z_at_line = 0;
  for (double t = 0; t < over.duration_s; t += 1e-3) {
    if (sim_over.BallAt(t).x() >= right->line_x_m) {
      z_at_line = sim_over.BallAt(t).z();
      break;
    }
  }
  ASSERT_GT(z_at_line, right->height_m + 0.3);
  Scene s = RunScene(sim_over, to, rng);
  Decisions d = MakeDecisions(s.track, s.result, &field, to, DecisionOptions());
  EXPECT_TRUE(d.goals.empty()) << "over the bar at z " << z_at_line;
  // Behind the line all along: thrown along y 0.5 m behind it.
  BallSimOptions behind;
  behind.start_m = {right->line_x_m + 0.5, -0.8, 0.11};
  behind.kicks = {{0.05, Eigen::Vector3d(0.0, 2.0, 3.0)}};
  behind.duration_s = 0.8;
  s = RunScene(BallSimulation(behind), to, rng);
  d = MakeDecisions(s.track, s.result, &field, to, DecisionOptions());
  EXPECT_TRUE(d.goals.empty());
  // Already in the goal when the track starts: no goal called, and the timeline says why.
  bool said = false;
  for (const auto& e : d.timeline) said |= e.text.find("already in") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(TrajectoryDecisions, InOrOutOfTheTouchLineByTheBallsFootprint) {
  testing::SeededRng rng(33);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  TrajectoryOptions to;
  int checked = 0;
  for (int trial = 0; trial < 6; ++trial) {
    BallSimOptions o;
    o.start_m = {rng.Uniform(-3, 3), 0.0, 0.11};
    const double T = 1.2, y_land = 0.5 * field.width_m + rng.Uniform(-0.35, 0.35);
    o.kicks = {{0.1, Eigen::Vector3d(1.0, y_land / T, 4.905 * T)}};
    o.duration_s = 1.5;
    const BallSimulation sim(o);
    const Scene s = RunScene(sim, to, rng);
    const Decisions d = MakeDecisions(s.track, s.result, &field, to, DecisionOptions());
    EXPECT_EQ(d.rule, "football");
    const FlightTruth& truth = sim.Flights().front();
    // Football: in while any part of the ball is over the line (outer edge at width/2).
    const double margin_true =
        0.5 * field.width_m + to.ball_radius_m - std::abs(truth.landing_m.y());
    ASSERT_FALSE(d.landings.empty());
    const LandingCall& c = d.landings.front();
    EXPECT_EQ(c.against, "playing area");
    EXPECT_NEAR(c.margin_m, margin_true, 0.02);
    if (std::abs(margin_true) > 0.03) {
      EXPECT_EQ(c.in, margin_true > 0) << "margin " << margin_true;
      ++checked;
    }
  }
  EXPECT_GE(checked, 2);
  DecisionOptions bad;
  bad.lines = {"no_such_line"};
  const std::vector<BallSample> none;
  EXPECT_THROW(MakeDecisions(none, TrajectoryResult(), &field, to, bad), Error);
}

TEST(TrajectoryDecisions, MadeShotPassesDownThroughTheRing) {
  testing::SeededRng rng(35);
  const field::FieldModel field = field::BuiltinField("basketball-fiba");
  ASSERT_FALSE(field.hoops.empty());
  const field::FieldHoop& hoop = field.hoops.front();
  TrajectoryOptions to;
  to.ball_radius_m = 0.12;
  for (const double miss : {0.0, 0.45}) {
    BallSimOptions o;
    o.ball_radius_m = 0.12;
    const Eigen::Vector3d from =
        hoop.centre_m + Eigen::Vector3d(-5.0 * (hoop.centre_m.x() > 0 ? 1 : -1), 1.0, -1.0);
    o.start_m = {from.x(), from.y(), 0.12};
    const double T = 1.1;
    const Eigen::Vector3d target = hoop.centre_m + Eigen::Vector3d(0, miss, 0);
    // Jump shot: kicked from the floor straight to the target (origin on the floor).
    const Eigen::Vector3d dp = target - o.start_m;
    o.kicks = {{0.1, Eigen::Vector3d(dp.x() / T, dp.y() / T, (dp.z() + 4.905 * T * T) / T)}};
    o.duration_s = 1.6;
    const BallSimulation sim(o);
    const Scene s = RunScene(sim, to, rng);
    const Decisions d = MakeDecisions(s.track, s.result, &field, to, DecisionOptions());
    EXPECT_EQ(d.rule, "basketball");
    if (miss == 0.0) {
      ASSERT_EQ(d.shots.size(), 1u);
      EXPECT_EQ(d.shots[0].hoop, hoop.name);
      EXPECT_LT(d.shots[0].offset_m, 0.03);
      EXPECT_TRUE(d.shots[0].clean);
      EXPECT_NEAR(d.shots[0].time_s, 0.1 + T, 0.01);
    } else {
      EXPECT_TRUE(d.shots.empty());
    }
  }
}

}  // namespace
}  // namespace fv::recon
