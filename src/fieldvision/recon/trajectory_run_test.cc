#include "fieldvision/recon/trajectory_run.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "fieldvision/recon/trajectory_sim.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv {
namespace {

TEST(TrajectoryRun, WritesTheContractJsonPicturesAndSmoothedTrack) {
  const uint64_t seed = testing::TestSeed(41);
  FV_SEED_TRACE(seed);
  Rng rng(seed);
  BallSimOptions o;
  o.start_m = {-6, -1, 0.11};
  o.kicks = {{0.2, {8, 1.5, 6}}};
  o.restitution = 0.6;
  o.duration_s = 2.5;
  const BallSimulation sim(o);
  const std::string dir = testing::TempDir();
  WriteBallTrack(dir + "/ball.csv", sim.Sample(50.0, 0.005, 0.05, 0.02, 0.5, rng));
  TrajectoryJob job;
  job.in_path = dir + "/ball.csv";
  job.out_path = dir + "/out/flights.json";
  job.field = "robocup-msl";
  job.images_dir = dir + "/img";
  job.smoothed_path = dir + "/out/smooth.csv";
  job.report_path = dir + "/out/report.json";
  std::ostringstream log;
  const TrajectoryJobResult r = RunTrajectory(job, log);
  EXPECT_NE(log.str().find("timeline"), std::string::npos);
  std::ifstream in(job.out_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_TRUE(j.is_array());
  ASSERT_GE(j.size(), 2u);
  double prev = -1;
  for (const auto& f : j) {
    for (const char* k : {"t_start_s", "t_end_s", "origin", "landing", "apex", "v0_mps", "rmse_m"})
      EXPECT_TRUE(f.contains(k)) << k;
    EXPECT_EQ(f["origin"].size(), 3u);
    EXPECT_NEAR(f["landing"][2].get<double>(), 0.11, 1e-3);
    EXPECT_GT(f["t_start_s"].get<double>(), prev);
    prev = f["t_start_s"].get<double>();
    EXPECT_FALSE(f["landing_calls"].empty());
  }
  const auto& t = sim.Flights().front();
  EXPECT_LT(
      (Eigen::Vector3d(j[0]["landing"][0], j[0]["landing"][1], j[0]["landing"][2]) - t.landing_m)
          .norm(),
      0.03);
  EXPECT_EQ(r.images.size(), 2 + r.result.flights.size());
  for (const auto& p : r.images) EXPECT_GT(std::filesystem::file_size(p), 1000u) << p;
  EXPECT_EQ(ReadBallTrack(job.smoothed_path).samples.size(), r.input.samples.size());
  EXPECT_TRUE(std::filesystem::exists(job.report_path));
  // Bad input: one line naming the file.
  job.in_path = dir + "/missing.csv";
  EXPECT_THROW(RunTrajectory(job, log), Error);
}

}  // namespace
}  // namespace fv
