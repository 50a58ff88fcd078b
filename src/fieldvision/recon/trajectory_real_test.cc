// Real table-tennis trajectories (TT3D, ../shared/data/tt3d-trajectories): segmentation at the
// table bounce and the hits, and the fit residual with and without drag.
#include <algorithm>
#include <filesystem>
#include <iostream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/trajectory_eval.h"
#include "fieldvision/recon/trajectory_io.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/testing.h"

namespace fv::recon {
namespace {

TrajectoryOptions TableTennis() {
  TrajectoryOptions o;
  o.ball_radius_m = 0.02;
  o.ground_z_m = 0.0;              // the table surface
  o.unmodelled_accel_mps2 = 25.0;  // drag and spin of a 2.7 g ball (as the CLI for TT3D files)
  o.drag = DragMode::kOn;          // fit both models on every flight
  o.ball_mass_kg = 0.0027;
  return o;
}

std::vector<std::string> Tt3dFiles() {
  std::vector<std::string> files;
  const std::string dir = testing::SharedDataDir();
  if (dir.empty()) return files;
  const std::string gt = dir + "/tt3d-trajectories/3D_gt";
  if (!std::filesystem::exists(gt)) return files;
  for (const auto& e : std::filesystem::directory_iterator(gt)) {
    if (e.path().extension() == ".csv") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The measures on every TT3D file: one bounce each, the pre-bounce residual of the
// chosen model near the free constant-acceleration fit, and the landing predicted from the first
// half of the flight against the bounce measured from the full track.
TEST(TrajectoryReal, Tt3dSpinModelResidualAndLandingFromTheFirstHalf) {
  const auto files = Tt3dFiles();
  if (files.empty()) GTEST_SKIP() << "no ../shared/data/tt3d-trajectories";
  TrajectoryOptions o = TableTennis();
  o.drag = DragMode::kAuto;
  std::vector<BounceTrackScore> scores;
  // Every third file keeps the test fast; bench_trajectory scores all of them.
  for (size_t i = 0; i < files.size(); i += 3) {
    scores.push_back(ScoreBounceTrack(files[i], ReadBallTrack(files[i]).samples, o));
  }
  const BounceTrackSummary sum = Summarize(scores);
  std::cout << sum.Table();
  EXPECT_EQ(sum.one_bounce, static_cast<int>(scores.size()));
  EXPECT_LE(sum.median_rmse_chosen_m, 0.006);
  EXPECT_LE(sum.median_pred_chosen_m, 0.10);
  EXPECT_LT(sum.median_pred_chosen_m, sum.median_pred_drag_m);
}

TEST(TrajectoryReal, Tt3dBounceOnTheTableIsFoundAndFitted) {
  const std::string dir = testing::SharedDataDir();
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data";
  const std::string path = dir + "/tt3d-trajectories/3D_gt/001.csv";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no " << path;
  const BallTrackFile file = ReadBallTrack(path);
  EXPECT_EQ(file.layout, "tt3d");
  EXPECT_TRUE(file.skipped.empty());
  const TrajectoryResult r = AnalyzeTrajectory(file.samples, TableTennis());
  SCOPED_TRACE(r.Summary());
  // 001: the ball flies over the net, bounces once on the table (lowest point 0.019 m at sample
  // 54, t = 12.363 s) and flies on towards the player.
  ASSERT_EQ(r.flights.size(), 2u);
  ASSERT_EQ(r.breaks.size(), 1u);
  EXPECT_EQ(r.breaks[0].kind, FlightEvent::kBounce);
  EXPECT_NEAR(r.breaks[0].time_s, file.samples[54].time_s, 0.01);
  EXPECT_NEAR(r.flights[0].landing_m.z(), 0.02, 1e-6);
  // The bounce point from both arcs near the lowest sample (the ball moves ~4 cm per frame; the
  // arcs bend with spin, which the model lacks).
  EXPECT_LT((r.flights[0].landing_m.head<2>() - file.samples[54].ball_in_world.head<2>()).norm(),
            0.08);
  for (const auto& f : r.flights) {
    EXPECT_TRUE(f.no_drag.ok);
    ASSERT_TRUE(f.with_drag.ok);
    // Drag matters for a 2.7 g ball: it must lower the residual; what is left is spin (Magnus).
    EXPECT_LT(f.with_drag.rmse_m, f.no_drag.rmse_m);
    EXPECT_LT(f.rmse_m, 0.03);
  }
}

// All files: prints the per-flight residuals (the numbers in the note).
TEST(TrajectoryReal, Tt3dAllFilesResiduals) {
  const std::string dir = testing::SharedDataDir();
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data";
  const std::string gt = dir + "/tt3d-trajectories/3D_gt";
  if (!std::filesystem::exists(gt)) GTEST_SKIP() << "no " << gt;
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(gt)) {
    if (e.path().extension() == ".csv") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  int flights = 0, bounces = 0, hits = 0, with_bounce = 0;
  std::vector<double> nd, wd;
  TrajectoryOptions o = TableTennis();
  o.spin = SpinMode::kOff;  // gravity against drag (the spin model: the test above)
  for (const auto& p : files) {
    const BallTrackFile file = ReadBallTrack(p);
    const TrajectoryResult r = AnalyzeTrajectory(file.samples, o);
    bool b = false;
    for (const auto& br : r.breaks) {
      bounces += br.kind == FlightEvent::kBounce;
      hits += br.kind == FlightEvent::kHit;
      b |= br.kind == FlightEvent::kBounce;
    }
    with_bounce += b;
    for (const auto& f : r.flights) {
      ++flights;
      if (!f.with_drag.ok) continue;  // paired: flights fitted with and without drag
      nd.push_back(f.no_drag.rmse_m);
      wd.push_back(f.with_drag.rmse_m);
    }
  }
  const auto median = [](std::vector<double> v) {
    return util::NearestRankPercentile(std::move(v), 0.5);
  };
  std::cout << fmt::format(
      "tt3d: {} files, {} flights, {} bounces, {} hits, {} files with a bounce; median rmse "
      "gravity {:.1f} mm, drag {:.1f} mm over {} flights fitted both ways (max {:.1f} / {:.1f} "
      "mm)\n",
      files.size(), flights, bounces, hits, with_bounce, median(nd) * 1e3, median(wd) * 1e3,
      nd.size(), nd.empty() ? 0.0 : *std::max_element(nd.begin(), nd.end()) * 1e3,
      wd.empty() ? 0.0 : *std::max_element(wd.begin(), wd.end()) * 1e3);
  // Every file has exactly one table bounce (checked by eye in the pictures).
  EXPECT_GE(with_bounce, static_cast<int>(files.size()) - 2);
  EXPECT_LT(median(wd), median(nd));
}

}  // namespace
}  // namespace fv::recon
