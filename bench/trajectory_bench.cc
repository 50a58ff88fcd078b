// Flight models on the real TT3D table-tennis tracks (../shared/data/tt3d-trajectories): the time
// to fit one pre-bounce flight with gravity only (the baseline), drag, and drag + spin (Magnus),
// and, printed before the timings, the accuracy table of every model on every track (pre-bounce
// residual, landing predicted from the first half against the measured bounce; trajectory_eval.h).
// Long tracks (issue 18): the whole `trajectory` job (read BALL.csv, analyse, predict, write
// FLIGHTS.json) on 20,000 rows of repeated kicks (the baseline) and on 2,000,000 rows, printed
// as the time per row against the baseline's (1.0: linear).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/trajectory_eval.h"
#include "fieldvision/recon/trajectory_io.h"
#include "fieldvision/recon/trajectory_run.h"
#include "fieldvision/recon/trajectory_sim.h"
#include "fieldvision/util/random.h"

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
  static const auto samples = [] {
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
  return samples;
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
    for (const auto& p : files) {
      scores.push_back(
          fv::recon::ScoreBounceTrack(p, fv::recon::ReadBallTrack(p).samples, TableTennis()));
    }
    std::cout << fv::recon::Summarize(scores).Table() << "\n";
  }
  benchmark::Initialize(&argc, argv);
  struct Reporter : benchmark::ConsoleReporter {
    std::map<std::string, double> s;  // real time per iteration, seconds
    void ReportRuns(const std::vector<Run>& runs) override {
      for (const auto& r : runs) s[r.benchmark_name()] = r.GetAdjustedRealTime();
      ConsoleReporter::ReportRuns(runs);
    }
  } reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  const auto base = reporter.s.find("BM_TrajectoryJob/20000/iterations:3/real_time");
  const auto big = reporter.s.find("BM_TrajectoryJob/2000000/iterations:1/real_time");
  if (base != reporter.s.end() && big != reporter.s.end() && base->second > 0) {
    printf("ratio trajectory 2,000,000 rows: %.1f s, %.2fx the time per row of 20,000 rows\n",
           big->second, big->second / 2e6 / (base->second / 2e4));
  }
  return 0;
}
