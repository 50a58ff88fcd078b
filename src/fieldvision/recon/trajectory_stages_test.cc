// AnalyzeTrajectory's stages one by one (trajectory_stages.h) on hand-made arcs.
#include "fieldvision/recon/trajectory_stages.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace fv::recon::detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A drag-free arc through p at time t0 with velocity v.
Flight Arc(double t0, const Eigen::Vector3d& p, const Eigen::Vector3d& v, double first_seen_s,
           double last_seen_s) {
  Flight f;
  f.no_drag.ok = true;
  f.no_drag.model.t0_s = t0;
  f.no_drag.model.p0_m = p;
  f.no_drag.model.v0_mps = v;
  f.t_first_seen_s = first_seen_s;
  f.t_last_seen_s = last_seen_s;
  return f;
}

TEST(TrajectoryStages, EndpointsAreWhereTheArcMeetsTheGround) {
  TrajectoryOptions o;
  const double zr = o.ground_z_m + o.ball_radius_m, g = o.gravity_mps2;
  Flight f = Arc(0.0, {0, 0, 1}, {5, 0, 4}, 0.0, 0.5);
  f.start_event = f.end_event = FlightEvent::kGround;
  PlaceEndpoints(o, -kInf, kInf, &f);
  EXPECT_NEAR(f.origin_m.z(), zr, 1e-6);
  EXPECT_NEAR(f.landing_m.z(), zr, 1e-6);
  EXPECT_LT(f.t_start_s, 0.0);
  EXPECT_GT(f.t_landing_s, 0.5);
  EXPECT_DOUBLE_EQ(f.t_end_s, f.t_landing_s);
  EXPECT_NEAR(f.t_apex_s, 4 / g, 0.003);
  EXPECT_NEAR(f.apex_m.z(), 1 + 8 / g, 1e-4);
  EXPECT_NEAR(f.speed_mps, f.v0_mps.norm(), 1e-12);
  EXPECT_FALSE(f.origin_extrapolated);
  EXPECT_FALSE(f.landing_extrapolated);
  // The first sample seen on the ground after the arc bounds the landing time (the arc crosses
  // the ground at 0.9975 s, 1.4 cm above it at 0.995 s).
  Flight bounded = Arc(0.0, {0, 0, 1}, {5, 0, 4}, 0.0, 0.5);
  bounded.start_event = bounded.end_event = FlightEvent::kGround;
  PlaceEndpoints(o, -kInf, 0.995, &bounded);
  EXPECT_DOUBLE_EQ(bounded.t_landing_s, 0.995);
  EXPECT_EQ(bounded.end_event, FlightEvent::kGround);
  // A bound while the arc is still 0.8 m up (a sample off it, then too few to fit): the flight
  // ended in the air there, and where it would have landed is extrapolated.
  Flight cut = Arc(0.0, {0, 0, 1}, {5, 0, 4}, 0.0, 0.5);
  cut.start_event = cut.end_event = FlightEvent::kGround;
  PlaceEndpoints(o, -kInf, 0.6, &cut);
  EXPECT_EQ(cut.end_event, FlightEvent::kHit);
  EXPECT_DOUBLE_EQ(cut.t_end_s, 0.6);
  EXPECT_NEAR(cut.landing_m.z(), zr, 1e-6);
  EXPECT_GT(cut.t_landing_s, 0.6);
  EXPECT_TRUE(cut.landing_extrapolated);
  // The same before the arc: it began in the air at the bound.
  PlaceEndpoints(o, -0.05, kInf, &cut);
  EXPECT_EQ(cut.start_event, FlightEvent::kHit);
  EXPECT_DOUBLE_EQ(cut.t_start_s, -0.05);
  // A flight that runs off the end of the track lands by extrapolation.
  Flight open = Arc(0.0, {0, 0, 1}, {5, 0, 4}, 0.0, 0.5);
  open.end_event = FlightEvent::kTrackEnd;
  PlaceEndpoints(o, -kInf, kInf, &open);
  EXPECT_TRUE(open.landing_extrapolated);
  EXPECT_TRUE(open.origin_extrapolated);  // kTrackStart
}

TEST(TrajectoryStages, ContactsAreBouncesOnTheGroundAndHitsInTheAir) {
  TrajectoryOptions o;
  const double zr = o.ground_z_m + o.ball_radius_m;
  // Down to the ground at t = 1 s and up again from there: a bounce.
  std::vector<Flight> flights = {Arc(1.0, {0, 0, zr}, {3, 0, -4}, 0.6, 0.98),
                                 Arc(1.0, {0, 0, zr}, {2.5, 0, 3}, 1.02, 1.4)};
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  std::vector<TrackBreak> breaks;
  ResolveContacts({0, 1}, o, 0.005, 0.02, &flights, &breaks);
  ASSERT_EQ(breaks.size(), 1u);
  EXPECT_EQ(breaks[0].kind, FlightEvent::kBounce);
  EXPECT_NEAR(breaks[0].time_s, 1.0, 1e-3);
  EXPECT_EQ(flights[0].end_event, FlightEvent::kBounce);
  EXPECT_EQ(flights[1].start_event, FlightEvent::kBounce);
  // Down at t = 1 s, up from 0.3 m further at 1.08 s (four sample intervals of 0.02 s later):
  // the arcs do not meet, a hop was not seen between them. Each arc keeps its ground crossing.
  flights = {Arc(1.0, {0, 0, zr}, {3, 0, -1.5}, 0.6, 0.98),
             Arc(1.08, {0.3, 0, zr}, {-4, 0, 3}, 1.12, 1.4)};
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  breaks.clear();
  ResolveContacts({0, 1}, o, 0.005, 0.02, &flights, &breaks);
  EXPECT_TRUE(breaks.empty());
  EXPECT_EQ(flights[0].end_event, FlightEvent::kGround);
  EXPECT_EQ(flights[1].start_event, FlightEvent::kGround);
  // A bounce whose arcs miss each other by 6 cm with crossings one interval apart (spin, drag,
  // a real ball's contact) stays a bounce.
  flights = {Arc(1.0, {0, 0, zr}, {3, 0, -1.5}, 0.6, 0.98),
             Arc(1.02, {0.06, 0, zr}, {2.5, 0, 3}, 1.04, 1.4)};
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  breaks.clear();
  ResolveContacts({0, 1}, o, 0.005, 0.02, &flights, &breaks);
  ASSERT_EQ(breaks.size(), 1u);
  EXPECT_EQ(breaks[0].kind, FlightEvent::kBounce);
  // The same turn 1.5 m up: a hit, which also ends and starts the flights.
  flights = {Arc(1.0, {0, 0, 1.5}, {3, 0, -1}, 0.6, 0.98),
             Arc(1.0, {0, 0, 1.5}, {-4, 0, 2}, 1.02, 1.4)};
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  breaks.clear();
  ResolveContacts({0, 1}, o, 0.005, 0.02, &flights, &breaks);
  ASSERT_EQ(breaks.size(), 1u);
  EXPECT_EQ(breaks[0].kind, FlightEvent::kHit);
  EXPECT_NEAR(flights[0].t_end_s, 1.0, 1e-3);
  EXPECT_DOUBLE_EQ(flights[1].t_start_s, flights[0].t_end_s);
  // A hop between them too short to fit (pieces 0 and 2): not resolved, ground contacts.
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  breaks.clear();
  ResolveContacts({0, 2}, o, 0.005, 0.02, &flights, &breaks);
  EXPECT_TRUE(breaks.empty());
  EXPECT_EQ(flights[0].end_event, FlightEvent::kGround);
  EXPECT_EQ(flights[1].start_event, FlightEvent::kGround);
}

TEST(TrajectoryStages, OutliersInAFlightsSpanJoinIt) {
  std::vector<BallSample> track(10);
  for (int i = 0; i < 10; ++i) track[i].time_s = 0.1 * i;
  std::vector<bool> outlier(10, false);
  outlier[2] = outlier[8] = true;
  Flight f;
  f.samples = {1, 3, 4, 5};
  f.t_first_seen_s = track[1].time_s;
  f.t_last_seen_s = track[5].time_s;
  AttachOutliers(track, outlier, &f);
  EXPECT_EQ(f.samples, (std::vector<int>{1, 2, 3, 4, 5}));  // 8 lies beyond the span
}

}  // namespace
}  // namespace fv::recon::detail
