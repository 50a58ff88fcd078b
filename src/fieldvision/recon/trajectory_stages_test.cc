// AnalyzeTrajectory's stages one by one (trajectory_stages.h) on hand-made arcs.
#include "fieldvision/recon/trajectory_stages.h"

#include <cmath>
#include <functional>
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
  // Still a ground contact there: the centre a radius up (CONTRACT.md), not the arc's 1.4 cm
  // above; likewise an arc started from a rolling ball's last sample 1.4 cm up.
  EXPECT_DOUBLE_EQ(bounded.landing_m.z(), zr);
  Flight rolled = Arc(0.0, {0, 0, 1}, {5, 0, 4}, 0.0, 0.5);
  rolled.start_event = rolled.end_event = FlightEvent::kGround;
  const double t_rise = (4 - std::sqrt(16 + 2 * g * (1 - zr))) / g;  // the arc leaves the ground
  PlaceEndpoints(o, t_rise + 0.002, kInf, &rolled);                  // 1.2 cm up there
  EXPECT_EQ(rolled.start_event, FlightEvent::kGround);
  EXPECT_DOUBLE_EQ(rolled.t_start_s, t_rise + 0.002);
  EXPECT_DOUBLE_EQ(rolled.origin_m.z(), zr);
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

std::function<Eigen::Vector3d(double)> Still(const Eigen::Vector3d& p) {
  return [p](double) { return p; };
}

// Samples every 0.02 s over [0.6, 1.4] s: on the first arc up to its last seen time, on the second
// from its first, and at between(t) in the span of neither.
std::vector<BallSample> TrackOf(const std::vector<Flight>& f,
                                const std::function<Eigen::Vector3d(double)>& between) {
  std::vector<BallSample> track;
  for (int i = 0; i <= 40; ++i) {
    BallSample s;
    s.frame = i;
    s.time_s = 0.6 + 0.02 * i;
    s.ball_in_world = s.time_s <= f[0].t_last_seen_s + 1e-9    ? f[0].model().PositionAt(s.time_s)
                      : s.time_s >= f[1].t_first_seen_s - 1e-9 ? f[1].model().PositionAt(s.time_s)
                                                               : between(s.time_s);
    track.push_back(s);
  }
  return track;
}

TEST(TrajectoryStages, ContactsAreBouncesOnTheGroundAndHitsInTheAir) {
  TrajectoryOptions o;
  const double zr = o.ground_z_m + o.ball_radius_m;
  // Down to the ground at t = 1 s and up again from there: a bounce.
  std::vector<Flight> flights = {Arc(1.0, {0, 0, zr}, {3, 0, -4}, 0.6, 0.98),
                                 Arc(1.0, {0, 0, zr}, {2.5, 0, 3}, 1.02, 1.4)};
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  std::vector<TrackBreak> breaks;
  ResolveContacts(TrackOf(flights, Still({})), {0, 1}, o, 0.005, &flights, &breaks);
  ASSERT_EQ(breaks.size(), 1u);
  EXPECT_EQ(breaks[0].kind, FlightEvent::kBounce);
  EXPECT_NEAR(breaks[0].time_s, 1.0, 1e-3);
  EXPECT_EQ(flights[0].end_event, FlightEvent::kBounce);
  EXPECT_EQ(flights[1].start_event, FlightEvent::kBounce);
  // Down at t = 1 s, then a hop from there kicked at 1.08 s, seen at 1.02-1.06 s only (off both
  // arcs): the bounce, the hop and the kick, where the hop meets the arc after it.
  BallisticModel hop;
  hop.t0_s = 1.0;
  hop.p0_m = {0, 0, zr};
  hop.v0_mps = {2, 0, 1.2};
  flights = {Arc(1.0, {0, 0, zr}, {3, 0, -1.5}, 0.6, 0.98),
             Arc(1.08, hop.PositionAt(1.08), {-4, 0, 3}, 1.12, 1.4)};
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  breaks.clear();
  const BallisticModel after = flights[1].model();
  ResolveContacts(
      TrackOf(flights,
              [&](double t) { return t < 1.08 - 1e-9 ? hop.PositionAt(t) : after.PositionAt(t); }),
      {0, 1}, o, 0.005, &flights, &breaks);
  ASSERT_EQ(breaks.size(), 2u);
  EXPECT_EQ(breaks[0].kind, FlightEvent::kBounce);
  EXPECT_NEAR(breaks[0].time_s, 1.0, 1e-3);
  EXPECT_EQ(breaks[1].kind, FlightEvent::kHit);
  EXPECT_NEAR(breaks[1].time_s, 1.08, 2e-3);
  EXPECT_EQ(flights[0].end_event, FlightEvent::kBounce);
  EXPECT_EQ(flights[1].start_event, FlightEvent::kHit);
  EXPECT_NEAR(flights[1].t_start_s, 1.08, 2e-3);
  // Samples between them off both arcs that no hop from the landing joins to the arc after (0.6
  // m up): two ground contacts, each arc's own crossing.
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  breaks.clear();
  ResolveContacts(TrackOf(flights, Still({0.15, 0, 0.6})), {0, 1}, o, 0.005, &flights, &breaks);
  EXPECT_TRUE(breaks.empty());
  EXPECT_EQ(flights[0].end_event, FlightEvent::kGround);
  EXPECT_EQ(flights[1].start_event, FlightEvent::kGround);
  // The same arcs with the samples between on the first one: nothing says a hop, a bounce.
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  breaks.clear();
  const BallisticModel first = flights[0].model();
  ResolveContacts(TrackOf(flights, [&](double t) { return first.PositionAt(t); }), {0, 1}, o, 0.005,
                  &flights, &breaks);
  ASSERT_EQ(breaks.size(), 1u);
  EXPECT_EQ(breaks[0].kind, FlightEvent::kBounce);
  // Arcs 6 cm apart crossing the ground one interval apart, no sample between them (spin, drag, a
  // real ball's contact): a bounce.
  flights = {Arc(1.0, {0, 0, zr}, {3, 0, -1.5}, 0.6, 0.98),
             Arc(1.02, {0.06, 0, zr}, {2.5, 0, 3}, 1.0, 1.4)};
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  breaks.clear();
  ResolveContacts(TrackOf(flights, Still({})), {0, 1}, o, 0.005, &flights, &breaks);
  ASSERT_EQ(breaks.size(), 1u);
  EXPECT_EQ(breaks[0].kind, FlightEvent::kBounce);
  // The same turn 1.5 m up: a hit, which also ends and starts the flights.
  flights = {Arc(1.0, {0, 0, 1.5}, {3, 0, -1}, 0.6, 0.98),
             Arc(1.0, {0, 0, 1.5}, {-4, 0, 2}, 1.02, 1.4)};
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  breaks.clear();
  ResolveContacts(TrackOf(flights, Still({})), {0, 1}, o, 0.005, &flights, &breaks);
  ASSERT_EQ(breaks.size(), 1u);
  EXPECT_EQ(breaks[0].kind, FlightEvent::kHit);
  EXPECT_NEAR(flights[0].t_end_s, 1.0, 1e-3);
  EXPECT_DOUBLE_EQ(flights[1].t_start_s, flights[0].t_end_s);
  // A hop between them too short to fit (pieces 0 and 2): not resolved, ground contacts.
  flights[0].end_event = flights[1].start_event = FlightEvent::kHit;
  breaks.clear();
  ResolveContacts(TrackOf(flights, Still({})), {0, 2}, o, 0.005, &flights, &breaks);
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
