#include "fieldvision/recon/trajectory_run.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <gtest/gtest.h>

#include "fieldvision/recon/standard_balls.h"
#include "fieldvision/recon/trajectory_run_internal.h"
#include "fieldvision/recon/trajectory_sim.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::recon {
namespace {

TEST(TrajectoryRun, WritesTheContractJsonPicturesAndSmoothedTrack) {
  testing::SeededRng rng(41);
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
    for (const char* k :
         {"t_start_s", "t_end_s", "origin", "landing", "apex", "v0_mps", "rmse_m"}) {
      EXPECT_TRUE(f.contains(k)) << k;
    }
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
  // A run that fails leaves the outputs of the last one as they were, and no temporary files.
  auto bytes = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  };
  const std::string flights_before = bytes(job.out_path);
  std::filesystem::remove_all(job.images_dir);
  std::ofstream(job.images_dir) << "a file where the pictures' folder should be";
  EXPECT_THROW(RunTrajectory(job, log), Error);
  EXPECT_EQ(bytes(job.out_path), flights_before);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir + "/out"),
                          std::filesystem::directory_iterator()),
            3);
  // Bad input: one line naming the file.
  job.in_path = dir + "/missing.csv";
  EXPECT_THROW(RunTrajectory(job, log), Error);
}

// Batch mode: a summary row per flight of the tracks that read; the failed ones are listed, and a
// batch of which none reads fails without a summary (it wrote one of nothing, exit 0).
TEST(TrajectoryRun, ABatchListsItsFailuresAndFailsWhenNothingFits) {
  testing::SeededRng rng(47);
  BallSimOptions o;
  o.start_m = {-6, -1, 0.11};
  o.kicks = {{0.2, {8, 1.5, 6}}};
  o.duration_s = 2.0;
  const BallSimulation sim(o);
  const std::string dir = testing::TempDir() + "/batch";
  std::filesystem::create_directories(dir);
  WriteBallTrack(dir + "/good.csv", sim.Sample(50.0, 0.005, 0.05, 0.02, 0.5, rng));
  std::ofstream(dir + "/junk.csv") << "not,a,ball,track\n1,2\n";
  TrajectoryJob job;
  job.out_path = dir + "/out";
  std::ostringstream log;
  const TrajectoryBatchResult r =
      RunTrajectoryBatch(job, {dir + "/good.csv", dir + "/junk.csv"}, log);
  ASSERT_EQ(r.failed.size(), 1u);
  EXPECT_NE(r.failed[0].find("junk.csv"), std::string::npos) << r.failed[0];
  EXPECT_TRUE(std::filesystem::exists(r.summary_csv));
  EXPECT_TRUE(std::filesystem::exists(dir + "/out/good.json"));
  std::ifstream summary(r.summary_csv);
  const std::string before((std::istreambuf_iterator<char>(summary)),
                           std::istreambuf_iterator<char>());
  try {
    RunTrajectoryBatch(job, {dir + "/junk.csv"}, log);
    ADD_FAILURE() << "a batch of which nothing reads passed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("none of the 1 tracks"), std::string::npos) << e.what();
  }
  std::ifstream again(r.summary_csv);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(again)), std::istreambuf_iterator<char>()),
            before);
}

// A ball that never rests (60 hops in one airborne block): every bounce is found. Finding the
// breaks took O(samples x breaks^2) (a 40,000-row track of such hops did not finish).
TEST(TrajectoryRun, LongBlockWithManyBounces) {
  testing::SeededRng rng(43);
  std::vector<BallSample> track;
  const double g = 9.81, r = 0.11, fps = 60;
  double t0 = 0, vz = 4.0;
  Eigen::Vector3d p0(-20, 0, r), v(3, 0.5, vz);
  int hops = 0;
  for (int i = 0; hops < 60; ++i) {
    const double t = i / fps;
    double dt = t - t0;
    if (dt > 2 * v.z() / g) {  // the bounce: a new hop from the contact point
      p0 += v * (2 * v.z() / g);
      p0.z() = r;
      t0 += 2 * v.z() / g;
      v = Eigen::Vector3d(rng.Uniform(-3, 3), rng.Uniform(-3, 3), rng.Uniform(3, 5));
      dt = t - t0;
      ++hops;
    }
    BallSample s;
    s.frame = i;
    s.time_s = t;
    s.ball_in_world = p0 + v * dt + Eigen::Vector3d(0, 0, -0.5 * g * dt * dt);
    for (int a = 0; a < 3; ++a) s.ball_in_world[a] += rng.Normal(0, 0.003);
    s.n_cams = 3;
    track.push_back(s);
  }
  TrajectoryOptions o;
  o.drag = DragMode::kOff;
  o.spin = SpinMode::kOff;
  o.noise_m = 0.003;
  size_t calls = 0;
  o.progress = [&calls](size_t, size_t) { ++calls; };
  const TrajectoryResult res = AnalyzeTrajectory(track, o);
  int bounces = 0;
  for (const auto& b : res.breaks) bounces += b.kind == FlightEvent::kBounce;
  EXPECT_GE(bounces, 58) << res.Summary();
  EXPECT_LE(static_cast<int>(res.breaks.size()), 61) << res.Summary();
  EXPECT_GE(res.flights.size(), 59u) << res.Summary();
  EXPECT_GE(calls, res.flights.size());
}

TEST(TrajectoryRunStages, OptionsFollowTheLayoutUnlessGiven) {
  TrajectoryJob job;
  std::ostringstream log;
  const TrajectoryOptions football = TrajectoryOptionsFor(job, "ball_csv", log);
  EXPECT_DOUBLE_EQ(football.ball_radius_m, 0.11);
  EXPECT_DOUBLE_EQ(football.ball_mass_kg, 0.43);
  EXPECT_DOUBLE_EQ(football.unmodelled_accel_mps2, 10.0);
  EXPECT_NE(log.str().find("football"), std::string::npos) << log.str();
  const TrajectoryOptions tt = TrajectoryOptionsFor(job, "tt3d", log);
  EXPECT_DOUBLE_EQ(tt.ball_radius_m, 0.02);
  EXPECT_DOUBLE_EQ(tt.ball_mass_kg, 0.0027);
  EXPECT_DOUBLE_EQ(tt.unmodelled_accel_mps2, 25.0);
  job.ball_diameter_m = 0.3;
  job.ball_mass_kg = 1.0;
  job.accel_slack_mps2 = 5.0;
  std::ostringstream quiet;
  const TrajectoryOptions given = TrajectoryOptionsFor(job, "tt3d", quiet);
  EXPECT_DOUBLE_EQ(given.ball_radius_m, 0.15);
  EXPECT_DOUBLE_EQ(given.ball_mass_kg, 1.0);
  EXPECT_DOUBLE_EQ(given.unmodelled_accel_mps2, 5.0);
  EXPECT_TRUE(quiet.str().empty()) << quiet.str();
  // A diameter without a mass takes the standard ball's of that size: a table-tennis track given
  // as BALL.csv with --ball-diameter 0.04 had a football's 0.43 kg (its spin 2657 rev/s).
  TrajectoryJob small;
  small.ball_diameter_m = 0.04;
  std::ostringstream said;
  EXPECT_DOUBLE_EQ(TrajectoryOptionsFor(small, "ball_csv", said).ball_mass_kg, 0.0027);
  EXPECT_NE(said.str().find("table-tennis"), std::string::npos) << said.str();
  small.ball_diameter_m = 0.0427;  // the SSL's golf ball
  EXPECT_NEAR(TrajectoryOptionsFor(small, "ball_csv", said).ball_mass_kg, 0.0459, 1e-4);
  // A football's mass on a TT3D file (its 4 cm by default) is warned of.
  TrajectoryJob heavy;
  heavy.ball_mass_kg = 0.43;
  std::ostringstream warned;
  TrajectoryOptionsFor(heavy, "tt3d", warned);
  EXPECT_NE(warned.str().find("warning: a ball of 0.040 m and 0.43 kg"), std::string::npos)
      << warned.str();
}

TEST(StandardBalls, NearestByDiameterAndOddMassesWarned) {
  EXPECT_STREQ(NearestStandardBall(0.040).name, "table-tennis");
  EXPECT_STREQ(NearestStandardBall(0.043).name, "golf (RoboCup SSL)");
  EXPECT_STREQ(NearestStandardBall(0.065).name, "tennis");
  EXPECT_STREQ(NearestStandardBall(0.22).name, "football (size 5)");
  EXPECT_STREQ(NearestStandardBall(0.24).name, "basketball (size 7)");
  EXPECT_STREQ(NearestStandardBall(5.0).name, "basketball (size 7)");
  EXPECT_THROW(NearestStandardBall(0.0), Error);
  EXPECT_THROW(NearestStandardBall(std::nan("")), Error);
  for (const double d : {0.040, 0.04267, 0.067, 0.2, 0.22, 0.239}) {
    EXPECT_EQ(BallMassWarning(d, NearestStandardBall(d).mass_kg), "") << d;
  }
  EXPECT_NE(BallMassWarning(0.04, 0.43).find("density of 12832 kg/m^3"), std::string::npos)
      << BallMassWarning(0.04, 0.43);
  EXPECT_NE(BallMassWarning(0.22, 0.0027), "");
}

}  // namespace
}  // namespace fv::recon
