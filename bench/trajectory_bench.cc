// Flight models on the real TT3D table-tennis tracks (../shared/data/tt3d-trajectories): the time
// to fit one pre-bounce flight with gravity only (the baseline), drag, and drag + spin (Magnus),
// and, printed before the timings, the accuracy table of every model on every track (pre-bounce
// residual, landing predicted from the first half against the measured bounce; trajectory_eval.h).
// Long tracks (issue 18): the whole `trajectory` job (read BALL.csv, analyse, predict, write
// FLIGHTS.json) on 20,000 rows of repeated kicks (the baseline) and on 2,000,000 rows, printed
// as the time per row against the baseline's (1.0: linear).
// A flight refined on its detections (the spin model over 4 cameras' reprojections, as `ball`
// refines each flight): every detection's residual read from one integrated path per evaluation
// (recon::FlightReprojection), printed as `x_jet`, its speed-up over the baseline in the same
// process, a Jet<10> Runge-Kutta integration from the reference time per detection.
#include <benchmark/benchmark.h>

#include <ceres/ceres.h>
#include <ctime>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "fieldvision/camera/projection.h"
#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/trajectory_eval.h"
#include "fieldvision/recon/trajectory_io.h"
#include "fieldvision/recon/trajectory_path.h"
#include "fieldvision/recon/trajectory_physics.h"
#include "fieldvision/recon/trajectory_run.h"
#include "fieldvision/recon/trajectory_sim.h"
#include "fieldvision/util/random.h"
#include "times_reporter.h"

namespace {

const std::string kGt = std::string(FV_SHARED_DATA_DIR) + "/tt3d-trajectories/3D_gt";

fv::recon::TrajectoryOptions TableTennis() {
  fv::recon::TrajectoryOptions o;
  o.ball_radius_m = 0.02;
  o.ball_mass_kg = 0.0027;
  o.unmodelled_accel_mps2 = 25.0;
  return o;
}

// The samples of 001.csv before its bounce.
const std::vector<fv::recon::BallSample>& Flight() {
  static const auto kSamples = [] {
    std::vector<fv::recon::BallSample> s;
    const std::string p = kGt + "/001.csv";
    if (!std::filesystem::exists(p)) return s;
    const auto track = fv::recon::ReadBallTrack(p).samples;
    const auto r = fv::recon::AnalyzeTrajectory(track, TableTennis());
    if (r.flights.empty()) return s;
    for (int k : r.flights[0].samples) {
      if (!r.outlier[k]) s.push_back(track[k]);
    }
    return s;
  }();
  return kSamples;
}

void Fit(benchmark::State& state, fv::recon::FlightModel kind) {
  const auto& s = Flight();
  if (s.empty()) {
    state.SkipWithError("no ../shared/data/tt3d-trajectories");
    return;
  }
  const double rmse_mm = fv::recon::FitBallistic(s, kind, TableTennis(), 0.002).rmse_m * 1e3;
  for (auto _ : state) {
    fv::recon::BallisticFit f = fv::recon::FitBallistic(s, kind, TableTennis(), 0.002);
    benchmark::DoNotOptimize(f.rmse_m);
  }
  state.counters["samples"] = static_cast<double>(s.size());
  state.counters["rmse_mm"] = rmse_mm;
}

void BM_FitGravity(benchmark::State& state) { Fit(state, fv::recon::FlightModel::kGravity); }
void BM_FitDrag(benchmark::State& state) { Fit(state, fv::recon::FlightModel::kDrag); }
void BM_FitSpin(benchmark::State& state) { Fit(state, fv::recon::FlightModel::kSpin); }
BENCHMARK(BM_FitGravity)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitDrag)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitSpin)->Unit(benchmark::kMillisecond);

// --- A flight refined on 4 cameras' detections ---

double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Detection {
  int cam;
  Eigen::Vector2d uv;
  double dt_s;
};

struct FlightScene {
  std::vector<fv::camera::Camera> cameras;
  std::vector<Detection> detections;
};

// A 1 s kick with backspin at 60 Hz seen by four corner cameras, centres with 0.3 px noise.
const FlightScene& KickScene() {
  static const FlightScene kScene = [] {
    FlightScene f;
    const Eigen::Vector3d eyes[4] = {{-12, -9, 5}, {12, -9, 5}, {12, 9, 5}, {-12, 9, 5}};
    for (const auto& eye : eyes) {
      fv::camera::Camera c = fv::camera::Camera::FromFov(1280, 960, 70);
      c.cam_from_world = fv::geometry::Rigid3d::LookAt(eye, {0, 0, 1});
      c.has_pose = true;
      f.cameras.push_back(c);
    }
    fv::util::Rng rng(7);
    const double p0[3] = {-6, -2, 0.11}, v0[3] = {14, 4, 7}, k = 0.012, s[3] = {0.5, -1.7, 0};
    for (int i = 0; i < 60; ++i) {
      const double t = i / 60.0;
      double p[3];
      fv::recon::FlightPositionAt(p0, v0, k, s, 9.81, t, true, p);
      for (int c = 0; c < 4; ++c) {
        const auto uv = f.cameras[c].Project(Eigen::Vector3d(p[0], p[1], p[2]));
        if (!uv) continue;
        f.detections.push_back(
            {c, *uv + Eigen::Vector2d(rng.Normal(0, 0.3), rng.Normal(0, 0.3)), t - 0.5});
      }
    }
    return f;
  }();
  return kScene;
}

// The baseline: one Jet integration from the reference time per detection.
struct JetReprojection {
  JetReprojection(const fv::camera::Camera& cam, const Eigen::Vector2d& uv, double dt)
      : uv_(uv), dt_(dt) {
    const auto block = cam.IntrinsicsBlock();
    std::copy(block.begin(), block.end(), intr_);
    const Eigen::Vector3d r = cam.cam_from_world.Rvec();
    for (int i = 0; i < 3; ++i) rv_[i] = r[i], tv_[i] = cam.cam_from_world.translation[i];
  }
  template <typename T>
  bool operator()(const T* p0, const T* v0, const T* k, const T* s, T* r) const {
    T p[3], intr[fv::camera::kNumIntrinsics], rv[3], tv[3], uv[2];
    fv::recon::FlightPositionAt(p0, v0, k[0], s, 9.81, dt_, true, p);
    for (int i = 0; i < fv::camera::kNumIntrinsics; ++i) intr[i] = T(intr_[i]);
    for (int i = 0; i < 3; ++i) rv[i] = T(rv_[i]), tv[i] = T(tv_[i]);
    if (!fv::camera::ProjectWorldPoint(intr, rv, tv, p, uv)) return false;
    r[0] = (uv[0] - uv_.x()) / 0.3;
    r[1] = (uv[1] - uv_.y()) / 0.3;
    return true;
  }
  Eigen::Vector2d uv_;
  double dt_;
  double intr_[fv::camera::kNumIntrinsics], rv_[3], tv_[3];
};

// Fits the spin model from a start 0.3 m and 1 m/s off; returns the position error at the
// reference time (m).
double RefineFlight(bool shared_path) {
  const FlightScene& f = KickScene();
  double p0[3] = {-6.3, -1.8, 0.4}, v0[3] = {13, 5, 6.5}, k[1] = {0.01}, s[3] = {0, 0, 0};
  std::vector<double> dt;
  for (const Detection& d : f.detections) dt.push_back(d.dt_s);
  fv::recon::FlightPath path(dt, 9.81);
  ceres::Problem problem;
  for (size_t i = 0; i < f.detections.size(); ++i) {
    const Detection& d = f.detections[i];
    ceres::CostFunction* cost =
        shared_path ? static_cast<ceres::CostFunction*>(new fv::recon::FlightReprojection(
                          &path, static_cast<int>(i), d.dt_s, 9.81, f.cameras[d.cam], d.uv, 0.3))
                    : new ceres::AutoDiffCostFunction<JetReprojection, 2, 3, 3, 1, 3>(
                          new JetReprojection(f.cameras[d.cam], d.uv, d.dt_s));
    problem.AddResidualBlock(cost, new ceres::HuberLoss(2.0), p0, v0, k, s);
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = 50;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  // The truth at the reference time (0.5 s into the kick).
  const double p_true[3] = {-6, -2, 0.11}, v_true[3] = {14, 4, 7}, s_true[3] = {0.5, -1.7, 0};
  double p_ref[3];
  fv::recon::FlightPositionAt(p_true, v_true, 0.012, s_true, 9.81, 0.5, true, p_ref);
  return std::hypot(p0[0] - p_ref[0], p0[1] - p_ref[1], p0[2] - p_ref[2]);
}

// Seconds (thread CPU) of the baseline's fit, median of 5, measured once.
double JetFitSeconds() {
  static const double kSeconds = [] {
    std::vector<double> t;
    for (int i = 0; i < 5; ++i) {
      const double t0 = ThreadCpuSeconds();
      benchmark::DoNotOptimize(RefineFlight(false));
      t.push_back(ThreadCpuSeconds() - t0);
    }
    std::nth_element(t.begin(), t.begin() + 2, t.end());
    return t[2];
  }();
  return kSeconds;
}

void BM_RefineFlightOnDetections(benchmark::State& state) {
  const bool shared = state.range(0) == 1;
  JetFitSeconds();
  double cpu = 0;
  for (auto _ : state) {
    const double t0 = ThreadCpuSeconds();
    benchmark::DoNotOptimize(RefineFlight(shared));
    cpu += ThreadCpuSeconds() - t0;
  }
  const double per_fit = cpu / std::max<int64_t>(state.iterations(), 1);
  state.counters["p_err_mm"] = 1e3 * RefineFlight(shared);
  state.counters["detections"] = static_cast<double>(KickScene().detections.size());
  state.counters["x_jet"] = JetFitSeconds() / per_fit;
  state.SetLabel(shared ? "one path per evaluation" : "baseline: a Jet integration per detection");
}
BENCHMARK(BM_RefineFlightOnDetections)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// A BALL.csv of `rows` rows at 100 Hz: eight random kicks with bounces, rolling and rest
// (5 mm noise, 1 % outliers), one after the other, each from where the one before stopped.
std::string LongTrackFile(long long rows) {
  static std::map<long long, std::string> files;
  if (files.count(rows)) return files[rows];
  std::vector<std::vector<fv::recon::BallSample>> kicks;
  std::vector<Eigen::Vector3d> shifts;
  fv::util::Rng rng(18);
  for (int k = 0; k < 8; ++k) {
    fv::recon::BallSimOptions o;
    o.start_m = Eigen::Vector3d(0, 0, 0.11);
    // One draw per statement, z first (GCC's order of a call's arguments; clang's differs).
    Eigen::Vector3d v;
    v.z() = rng.Uniform(3, 10);
    v.y() = rng.Uniform(-8, 8);
    v.x() = rng.Uniform(-12, 12);
    o.kicks = {{0.3, v}};
    o.restitution = 0.6;
    o.rolling_decel_mps2 = 3.0;
    o.duration_s = 5.0;
    const fv::recon::BallSimulation sim(o);
    kicks.push_back(sim.Sample(100.0, 0.005, 0.0, 0.01, 0.5, rng));
    shifts.push_back(sim.BallAt(o.duration_s) - o.start_m);
  }
  std::vector<fv::recon::BallSample> track;
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
  double t0 = 0.0;
  for (long long k = 0; static_cast<long long>(track.size()) < rows; ++k) {
    const auto& kick = kicks[k % kicks.size()];
    for (fv::recon::BallSample s : kick) {
      if (static_cast<long long>(track.size()) >= rows) break;
      s.time_s += t0;
      s.frame = static_cast<long long>(track.size());
      s.ball_in_world += at;
      track.push_back(s);
    }
    t0 = track.back().time_s + 0.01;
    at += shifts[k % kicks.size()];
    if (at.head<2>().norm() > 40) at = Eigen::Vector3d::Zero();  // stay near the field
  }
  const std::string path =
      (std::filesystem::temp_directory_path() / ("fv_bench_track_" + std::to_string(rows) + ".csv"))
          .string();
  fv::recon::WriteBallTrack(path, track);
  return files[rows] = path;
}

// The `trajectory` job on a long track; counters: rows, flights, seconds per million rows.
void BM_TrajectoryJob(benchmark::State& state) {
  fv::recon::TrajectoryJob job;
  job.in_path = LongTrackFile(state.range(0));
  job.out_path = job.in_path + ".json";
  size_t flights = 0;
  for (auto _ : state) {
    std::ostringstream log;
    flights = fv::recon::RunTrajectory(job, log).result.flights.size();
  }
  state.counters["rows"] = static_cast<double>(state.range(0));
  state.counters["flights"] = static_cast<double>(flights);
  state.counters["s_per_Mrow"] = benchmark::Counter(
      static_cast<double>(state.range(0)) * 1e-6,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_TrajectoryJob)->Arg(20000)->Iterations(3)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_TrajectoryJob)->Arg(2000000)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  if (std::filesystem::exists(kGt)) {
    std::vector<std::string> files;
    for (const auto& e : std::filesystem::directory_iterator(kGt)) {
      if (e.path().extension() == ".csv") files.push_back(e.path().string());
    }
    std::sort(files.begin(), files.end());
    std::vector<fv::recon::BounceTrackScore> scores;
    scores.reserve(files.size());
    for (const auto& p : files) {
      scores.push_back(
          fv::recon::ScoreBounceTrack(p, fv::recon::ReadBallTrack(p).samples, TableTennis()));
    }
    std::cout << fv::recon::Summarize(scores).Table() << "\n";
  }
  benchmark::Initialize(&argc, argv);
  fv::bench::TimesReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  const auto base = reporter.times.find("BM_TrajectoryJob/20000/iterations:3/real_time");
  const auto big = reporter.times.find("BM_TrajectoryJob/2000000/iterations:1/real_time");
  if (base != reporter.times.end() && big != reporter.times.end() && base->second > 0) {
    printf("ratio trajectory 2,000,000 rows: %.1f s, %.2fx the time per row of 20,000 rows\n",
           big->second, big->second / 2e6 / (base->second / 2e4));
  }
  return 0;
}
