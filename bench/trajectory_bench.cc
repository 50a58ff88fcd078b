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
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
