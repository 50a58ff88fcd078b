#include "fieldvision/recon/trajectory_path.h"

#include <algorithm>
#include <cmath>

#include <ceres/ceres.h>
#include <ceres/jet.h>
#include <gtest/gtest.h>

#include "fieldvision/camera/projection.h"
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

// A detection's reprojection residual from the shared path has the values and derivatives of a
// Jet integration of its own through the camera (a distorted one), for each model: the spin
// model's path, the drag model's (no derivatives by s) and the drag-free parabola (no path).
TEST(FlightReprojection, MatchesAJetThroughTheCamera) {
  testing::SeededRng rng(11);
  const double g = 9.81;
  camera::Camera cam = camera::Camera::FromFov(1280, 960, 70);
  cam.distortion = {-0.12, 0.05, 0.001, -0.002, 0.0};
  cam.cam_from_world = geometry::Rigid3d::LookAt(Eigen::Vector3d(-3, -12, 4), {4, 0, 1});
  cam.has_pose = true;
  const double p0[3] = {0.5, -1.0, 0.2}, v0[3] = {14.0, 3.0, 7.0}, k[1] = {0.015};
  const double s[3] = {0.4, -0.3, 0.6};
  const double* params[4] = {p0, v0, k, s};
  std::vector<double> dt;
  for (int i = -20; i <= 40; ++i) dt.push_back(i / 60.0 + rng.Uniform(-0.003, 0.003));
  const Eigen::Vector2d uv(640.0, 480.0);
  const double sigma = 0.7;
  FlightPath path(dt, g);
  using Jet = ceres::Jet<double, 10>;
  Jet jp0[3], jv0[3], jk(k[0], 6), js[3], intr[camera::kNumIntrinsics], rv[3], tv[3];
  for (int j = 0; j < 3; ++j) {
    jp0[j] = Jet(p0[j], j);
    jv0[j] = Jet(v0[j], 3 + j);
    js[j] = Jet(s[j], 7 + j);
  }
  const auto block = cam.IntrinsicsBlock();
  for (int i = 0; i < camera::kNumIntrinsics; ++i) intr[i] = Jet(block[i]);
  const Eigen::Vector3d r = cam.cam_from_world.Rvec();
  for (int j = 0; j < 3; ++j) rv[j] = Jet(r[j]), tv[j] = Jet(cam.cam_from_world.translation[j]);
  for (const bool integrate : {true, false}) {
    for (size_t i = 0; i < dt.size(); ++i) {
      const FlightReprojection cost(integrate ? &path : nullptr, static_cast<int>(i), dt[i], g, cam,
                                    uv, sigma);
      double res[2], j0[6], j1[6], j2[2], j3[6];
      double* jac[4] = {j0, j1, j2, j3};
      ASSERT_TRUE(cost.Evaluate(params, res, jac)) << "dt " << dt[i];
      Jet p[3], want[2];
      FlightPositionAt(jp0, jv0, jk, js, g, dt[i], integrate, p);
      ASSERT_TRUE(camera::ProjectWorldPoint(intr, rv, tv, p, want));
      for (int row = 0; row < 2; ++row) {
        const Jet e = (want[row] - uv[row]) / sigma;
        EXPECT_NEAR(res[row], e.a, 1e-6) << "dt " << dt[i] << " integrate " << integrate;
        const double scale = e.v.cwiseAbs().maxCoeff();
        for (int c = 0; c < 10; ++c) {
          const double got = c < 3    ? j0[row * 3 + c]
                             : c < 6  ? j1[row * 3 + c - 3]
                             : c == 6 ? j2[row]
                                      : j3[row * 3 + c - 7];
          EXPECT_NEAR(got, e.v[c], 1e-6 * scale) << "dt " << dt[i] << " c " << c;
        }
      }
    }
  }
  // Without derivatives by s (a drag fit holds s constant): the others are the same.
  FlightPath drag(dt, g);
  const FlightReprojection with_spin(&path, 7, dt[7], g, cam, uv, sigma);
  const FlightReprojection no_spin(&drag, 7, dt[7], g, cam, uv, sigma);
  double a[2], b[2], a0[6], a1[6], a2[2], a3[6], b0[6], b1[6], b2[2];
  double* ja[4] = {a0, a1, a2, a3};
  double* jb[4] = {b0, b1, b2, nullptr};
  ASSERT_TRUE(with_spin.Evaluate(params, a, ja));
  ASSERT_TRUE(no_spin.Evaluate(params, b, jb));
  for (int c = 0; c < 6; ++c) EXPECT_DOUBLE_EQ(a0[c], b0[c]);
  EXPECT_DOUBLE_EQ(a2[1], b2[1]);
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

// A drag or spin fit as it was before FitBallistic put all samples in one residual block and
// integrated in steps of kMaxStepS = 10 ms: a residual block per sample under its own Huber loss,
// the position integrated from the reference time in 2 ms steps, each stage from the one before
// (gravity, drag from k = 0.01, spin from no spin).
struct FitBefore {
  struct Residual {
    template <typename T>
    bool operator()(const T* p0, const T* v0, const T* k, const T* s, T* r) const {
      T p[3] = {p0[0], p0[1], p0[2]}, v[3] = {v0[0], v0[1], v0[2]};
      const int steps = std::max(1, static_cast<int>(std::ceil(std::abs(dt) / step_s)));
      for (int i = 0; i < steps; ++i) FlightRk4Step(p, v, k[0], s, g, dt / steps);
      for (int j = 0; j < 3; ++j) r[j] = p[j] - x[j];
      return true;
    }
    Eigen::Vector3d x;
    double dt, g, step_s;
  };

  // Solves from `start` (at the samples' reference time) for the drag (and the spin) model.
  // converged: to tolerances far below Ceres's defaults (the bounded solve creeps along k = 0),
  // in steps of step_s (2 ms before; any step integrates a parabola exactly).
  static BallisticModel Solve(const std::vector<BallSample>& samples, const BallisticModel& start,
                              bool spin, const TrajectoryOptions& o, double noise_m,
                              bool converged = false, double step_s = 0.002) {
    const int n = static_cast<int>(samples.size());
    const double t_ref = samples[n / 2].time_s, c_m = o.MagnusPerRad();
    double p0[3], v0[3], k[1] = {start.drag_per_m}, s[3] = {0, 0, 0};
    for (int j = 0; j < 3; ++j) p0[j] = start.p0_m[j], v0[j] = start.v0_mps[j];
    ceres::Problem problem;
    for (const BallSample& b : samples) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<Residual, 3, 3, 3, 1, 3>(
              new Residual{b.ball_in_world, b.time_s - t_ref, o.gravity_mps2, step_s}),
          new ceres::HuberLoss(3.0 * std::max(noise_m, 1e-3)), p0, v0, k, s);
    }
    problem.SetParameterLowerBound(k, 0, 0.0);
    problem.SetParameterUpperBound(k, 0, o.max_drag_per_m);
    if (spin) {
      const double unit = std::max(noise_m, 1e-3) / (c_m * 2 * M_PI);
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<SpinPrior, 3, 3>(new SpinPrior(
                                   start.v0_mps.normalized(), unit / o.spin_prior_revps,
                                   unit / o.spin_along_prior_revps)),
                               nullptr, s);
    } else {
      problem.SetParameterBlockConstant(s);
    }
    ceres::Solver::Options so;
    so.max_num_iterations = o.max_iterations;
    so.linear_solver_type = ceres::DENSE_QR;
    so.logging_type = ceres::SILENT;
    if (converged) {
      so.max_num_iterations = 100;
      so.function_tolerance = so.gradient_tolerance = so.parameter_tolerance = 1e-15;
    }
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    BallisticModel m = start;
    m.t0_s = t_ref;
    m.p0_m = {p0[0], p0[1], p0[2]};
    m.v0_mps = {v0[0], v0[1], v0[2]};
    m.drag_per_m = k[0];
    if (spin) {
      m.magnus_per_rad = c_m;
      m.spin_radps = Eigen::Vector3d(s[0], s[1], s[2]) / c_m;
    }
    return m;
  }
};

// The drag and spin fits of a football kick and of a table-tennis stroke (strong spin: the largest
// error of 10 ms steps, about 1 um over the flight), with noise and two outliers, are those of the
// fit before (FitBefore): parameters within 1 um, 1 um/s, 1e-6 /m and 1e-3 rad/s (noise-sized
// changes are 1000 times larger; measured: below 1e-10 m, 2e-8 m/s, 1e-9 /m, 3e-7 rad/s).
TEST(FlightPath, OneBlockInTenMsStepsFitsAsBlocksPerSampleInTwoMsSteps) {
  testing::SeededRng rng(18);
  for (const bool table_tennis : {false, true}) {
    SCOPED_TRACE(table_tennis ? "table tennis" : "football");
    TrajectoryOptions o;
    if (table_tennis) {
      o.ball_radius_m = 0.02;
      o.ball_mass_kg = 0.0027;
    }
    BallisticModel truth;
    truth.p0_m = table_tennis ? Eigen::Vector3d(0.1, -1.6, 0.3) : Eigen::Vector3d(-10, -3, 0.2);
    truth.v0_mps = table_tennis ? Eigen::Vector3d(0.2, 8, 1.0) : Eigen::Vector3d(20, 4, 9);
    truth.drag_per_m = table_tennis ? 0.11 : 0.015;
    truth.magnus_per_rad = o.MagnusPerRad();
    truth.spin_radps =
        2 * M_PI * (table_tennis ? Eigen::Vector3d(-60, 0, 20) : Eigen::Vector3d(0, 2, 6));
    const double noise = table_tennis ? 0.002 : 0.005, fps = table_tennis ? 120 : 100;
    const int n = table_tennis ? 50 : 70;
    std::vector<BallSample> samples(n);
    for (int i = 0; i < n; ++i) {
      samples[i].time_s = i / fps;
      const double dz = rng.Normal(0, noise), dy = rng.Normal(0, noise), dx = rng.Normal(0, noise);
      samples[i].ball_in_world = truth.PositionAt(samples[i].time_s) + Eigen::Vector3d(dx, dy, dz);
    }
    samples[n / 3].ball_in_world.z() += 0.1;
    samples[2 * n / 3].ball_in_world.x() -= 0.08;
    const BallisticFit gravity = FitBallistic(samples, FlightModel::kGravity, o, noise);
    const BallisticFit drag = FitBallistic(samples, FlightModel::kDrag, o, noise, &gravity.model);
    const BallisticFit spin = FitBallistic(samples, FlightModel::kSpin, o, noise, &drag.model);
    ASSERT_TRUE(gravity.ok && drag.ok && spin.ok);
    BallisticModel start = gravity.model;
    start.drag_per_m = 0.01;
    const BallisticModel drag_before = FitBefore::Solve(samples, start, false, o, noise);
    const BallisticModel spin_before = FitBefore::Solve(samples, drag_before, true, o, noise);
    for (const auto& [fit, before] : {std::pair{&drag, &drag_before}, {&spin, &spin_before}}) {
      EXPECT_EQ(fit->model.t0_s, before->t0_s);
      EXPECT_LT((fit->model.p0_m - before->p0_m).norm(), 1e-6);
      EXPECT_LT((fit->model.v0_mps - before->v0_mps).norm(), 1e-6);
      EXPECT_NEAR(fit->model.drag_per_m, before->drag_per_m, 1e-6);
      EXPECT_LT((fit->model.spin_radps - before->spin_radps).norm(), 1e-3);
    }
    EXPECT_EQ(spin.inliers, n - 2);  // the outliers (the drag fit misses the spin by more)
  }
}

// A flight the drag model fits best without drag (k at its bound 0): the drag fit is the gravity
// fit (no solve: the cost rises with k there) and the spin fit is solved with k held at 0. Both
// reach a lower cost than the bounded solve of the fit before, even run to convergence: that one
// stalls on the bound (its k projected to 0 after each step) centimetres from the optimum.
TEST(FlightPath, DragFreeFlightFitsAtTheBoundBetterThanTheBoundedSolve) {
  testing::SeededRng rng(19);
  TrajectoryOptions o;
  BallisticModel truth;
  truth.p0_m = {-10, -3, 0.2};
  truth.v0_mps = {15, 4, 8};
  truth.drag_per_m = -0.004;  // a push along the flight: no drag fits best
  const double noise = 0.005;
  std::vector<BallSample> samples(60);
  for (size_t i = 0; i < samples.size(); ++i) {
    samples[i].time_s = i / 100.0;
    const double dz = rng.Normal(0, noise), dy = rng.Normal(0, noise), dx = rng.Normal(0, noise);
    samples[i].ball_in_world = truth.PositionAt(samples[i].time_s) + Eigen::Vector3d(dx, dy, dz);
  }
  const BallisticFit gravity = FitBallistic(samples, FlightModel::kGravity, o, noise);
  const BallisticFit drag = FitBallistic(samples, FlightModel::kDrag, o, noise, &gravity.model);
  const BallisticFit spin = FitBallistic(samples, FlightModel::kSpin, o, noise, &gravity.model);
  ASSERT_TRUE(gravity.ok && drag.ok && spin.ok);
  EXPECT_EQ(drag.model.drag_per_m, 0.0);
  EXPECT_LT((drag.model.p0_m - gravity.model.p0_m).norm(), 1e-9);
  EXPECT_LT((drag.model.v0_mps - gravity.model.v0_mps).norm(), 1e-9);
  EXPECT_EQ(drag.model.drag_per_m, spin.model.drag_per_m);
  // The fits' robust cost (and the spin prior's, the same direction for both).
  const double a = 3.0 * noise, unit = noise / (o.MagnusPerRad() * 2 * M_PI);
  const SpinPrior prior(gravity.model.v0_mps.normalized(), unit / o.spin_prior_revps,
                        unit / o.spin_along_prior_revps);
  auto cost = [&](const BallisticModel& m) {
    double c = 0.0;
    for (const BallSample& b : samples) {
      const double r2 = (m.PositionAt(b.time_s) - b.ball_in_world).squaredNorm();
      c += 0.5 * (r2 <= a * a ? r2 : 2 * a * std::sqrt(r2) - a * a);
    }
    const Eigen::Vector3d s = m.magnus_per_rad * m.spin_radps;
    Eigen::Vector3d r;
    prior(s.data(), r.data());
    return c + 0.5 * r.squaredNorm();
  };
  BallisticModel pushed = drag.model;
  pushed.drag_per_m = 1e-4;
  EXPECT_GT(cost(pushed), cost(drag.model));
  BallisticModel start = gravity.model;
  start.drag_per_m = 0.01;
  // (Steps of 0.1 s: near k = 0 and without spin the path is all but a parabola.)
  const BallisticModel drag_before = FitBefore::Solve(samples, start, false, o, noise, true, 0.1);
  start.drag_per_m = 0.0;
  const BallisticModel spin_before = FitBefore::Solve(samples, start, true, o, noise, true, 0.1);
  EXPECT_LT(cost(drag.model), cost(drag_before));
  EXPECT_LE(cost(spin.model), cost(spin_before) * (1 + 1e-12));
}

}  // namespace
}  // namespace fv::recon
