#include "fieldvision/recon/trajectory_path.h"

#include <algorithm>

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/trajectory_physics.h"
#include "fieldvision/recon/trajectory_sim.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::recon {
namespace {

// The path through shuffled sample times on both sides of the reference time gives each sample's
// position and derivatives as one integration per sample from the reference time did.
TEST(FlightPath, MatchesOneIntegrationPerSample) {
  testing::SeededRng rng(5);
  const double g = 9.81;
  const double p0[3] = {1.0, -2.0, 3.0}, v0[3] = {12.0, 3.0, 6.0}, k[1] = {0.02};
  const double s[3] = {0.3, -0.2, 0.5};
  const double* params[4] = {p0, v0, k, s};
  std::vector<double> dt;
  for (int i = -40; i <= 60; ++i) dt.push_back(0.0101 * i + rng.Uniform(-0.002, 0.002));
  std::shuffle(dt.begin(), dt.end(), rng.engine());
  FlightPath path(dt, g);
  path.Update(params, FlightPath::Need::kAll);
  using Jet = ceres::Jet<double, 10>;
  Jet jp0[3], jv0[3], jk(k[0], 6), js[3];
  for (int j = 0; j < 3; ++j) {
    jp0[j] = Jet(p0[j], j);
    jv0[j] = Jet(v0[j], 3 + j);
    js[j] = Jet(s[j], 7 + j);
  }
  for (size_t i = 0; i < dt.size(); ++i) {
    Jet p[3];
    FlightPositionAt(jp0, jv0, jk, js, g, dt[i], true, p);
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(path.Position(i)[j], p[j].a, 1e-9) << "dt " << dt[i];
      for (int c = 0; c < 10; ++c) {
        EXPECT_NEAR(path.Derivatives(i)(j, c), p[j].v[c], 1e-8) << "dt " << dt[i] << " c " << c;
      }
    }
  }
  EXPECT_EQ(path.sweeps(), 1);
  // The same values again: nothing integrated; fewer derivatives: nothing either.
  path.Update(params, FlightPath::Need::kNoSpin);
  EXPECT_EQ(path.sweeps(), 1);
  // Without derivatives by s (held constant): the others are the same, those by s zero.
  FlightPath drag(dt, g);
  drag.Update(params, FlightPath::Need::kNoSpin);
  for (size_t i = 0; i < dt.size(); ++i) {
    EXPECT_EQ(drag.Position(i), path.Position(i));
    EXPECT_EQ(drag.Derivatives(i).leftCols<7>(), path.Derivatives(i).leftCols<7>());
    EXPECT_TRUE(drag.Derivatives(i).rightCols<3>().isZero());
  }
}

// The work of a drag or spin fit grows with the flight's span, not with samples x span (each
// sample's residual was an integration of its own from the reference time): four times the
// frame rate over the same flight costs at most a step per sample more per evaluation.
TEST(FlightPath, FitWorkPerEvaluationFollowsTheSpan) {
  testing::SeededRng rng(9);
  BallSimOptions o;
  o.start_m = {-8, -2, 0.11};
  o.kicks = {{0.05, {18, 2, 9}}};
  o.drag_per_m = 0.015;
  o.duration_s = 1.6;
  const BallSimulation sim(o);
  TrajectoryOptions opt;
  for (const double fps : {100.0, 400.0}) {
    SCOPED_TRACE(fps);
    std::vector<BallSample> flight;
    for (const auto& s : sim.Sample(fps, 0.003, 0.0, 0.0, 0.0, rng)) {
      if (s.time_s > 0.1 && s.time_s < 1.5) flight.push_back(s);
    }
    const double span = flight.back().time_s - flight.front().time_s;
    const double n = static_cast<double>(flight.size());
    for (const FlightModel kind : {FlightModel::kDrag, FlightModel::kSpin}) {
      const BallisticFit fit = FitBallistic(flight, kind, opt, 0.003);
      ASSERT_TRUE(fit.ok);
      ASSERT_GT(fit.path_sweeps, 0);
      const double per_sweep =
          static_cast<double>(fit.path_steps) / static_cast<double>(fit.path_sweeps);
      EXPECT_LE(per_sweep, span / kMaxStepS + n + 2);
    }
  }
}

// A model walked through increasing times (BallisticModel::PositionsAt, Advance) is where one
// integration from t0 per time puts it; a parabola exactly.
TEST(FlightPath, ModelWalkMatchesPositionAt) {
  BallisticModel m;
  m.t0_s = 1.0;
  m.p0_m = {1, 2, 3};
  m.v0_mps = {12, -3, 6};
  std::vector<double> times;
  for (int i = 0; i <= 300; ++i) times.push_back(0.4 + 0.0037 * i);
  for (const bool spin : {false, true}) {
    SCOPED_TRACE(spin);
    m.drag_per_m = spin ? 0.02 : 0.0;
    m.magnus_per_rad = spin ? 0.006 : 0.0;
    m.spin_radps = spin ? Eigen::Vector3d(20, -40, 60) : Eigen::Vector3d::Zero();
    const auto walked = m.PositionsAt(times);
    ASSERT_EQ(walked.size(), times.size());
    for (size_t i = 0; i < times.size(); ++i) {
      const Eigen::Vector3d p = m.PositionAt(times[i]);
      if (spin) {
        EXPECT_LT((walked[i] - p).norm(), 1e-9) << times[i];
      } else {
        EXPECT_EQ(walked[i], p) << times[i];
      }
    }
  }
}

}  // namespace
}  // namespace fv::recon
