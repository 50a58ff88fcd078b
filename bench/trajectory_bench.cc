// Flight models on the real TT3D table-tennis tracks (../shared/data/tt3d-trajectories): the time
// to fit one pre-bounce flight with gravity only (the baseline), drag, and drag + spin (Magnus),
// and, printed before the timings, the accuracy table of every model on every track (pre-bounce
// residual, landing predicted from the first half against the measured bounce; trajectory_eval.h).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <iostream>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/trajectory_eval.h"
#include "fieldvision/recon/trajectory_io.h"

namespace {

const std::string kGt = std::string(FV_SHARED_DATA_DIR) + "/tt3d-trajectories/3D_gt";

fv::TrajectoryOptions TableTennis() {
  fv::TrajectoryOptions o;
  o.ball_radius_m = 0.02;
  o.ball_mass_kg = 0.0027;
  o.unmodelled_accel_mps2 = 25.0;
  return o;
}

// The samples of 001.csv before its bounce.
const std::vector<fv::BallSample>& Flight() {
  static const auto samples = [] {
    std::vector<fv::BallSample> s;
    const std::string p = kGt + "/001.csv";
    if (!std::filesystem::exists(p)) return s;
    const auto track = fv::ReadBallTrack(p).samples;
    const auto r = fv::AnalyzeTrajectory(track, TableTennis());
    if (r.flights.empty()) return s;
    for (int k : r.flights[0].samples) {
      if (!r.outlier[k]) s.push_back(track[k]);
    }
    return s;
  }();
  return samples;
}

void Fit(benchmark::State& state, fv::FlightModel kind) {
  const auto& s = Flight();
  if (s.empty()) {
    state.SkipWithError("no ../shared/data/tt3d-trajectories");
    return;
  }
  const double rmse_mm = fv::FitBallistic(s, kind, TableTennis(), 0.002).rmse_m * 1e3;
  for (auto _ : state) {
    fv::BallisticFit f = fv::FitBallistic(s, kind, TableTennis(), 0.002);
    benchmark::DoNotOptimize(f.rmse_m);
  }
  state.counters["samples"] = static_cast<double>(s.size());
  state.counters["rmse_mm"] = rmse_mm;
}

void BM_FitGravity(benchmark::State& state) { Fit(state, fv::FlightModel::kGravity); }
void BM_FitDrag(benchmark::State& state) { Fit(state, fv::FlightModel::kDrag); }
void BM_FitSpin(benchmark::State& state) { Fit(state, fv::FlightModel::kSpin); }
BENCHMARK(BM_FitGravity)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitDrag)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitSpin)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  if (std::filesystem::exists(kGt)) {
    std::vector<std::string> files;
    for (const auto& e : std::filesystem::directory_iterator(kGt)) {
      if (e.path().extension() == ".csv") files.push_back(e.path().string());
    }
    std::sort(files.begin(), files.end());
    std::vector<fv::BounceTrackScore> scores;
    for (const auto& p : files) {
      scores.push_back(fv::ScoreBounceTrack(p, fv::ReadBallTrack(p).samples, TableTennis()));
    }
    std::cout << fv::Summarize(scores).Table() << "\n";
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
