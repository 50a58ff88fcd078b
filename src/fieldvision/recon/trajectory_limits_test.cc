// Issue 18: trajectory options out of any physical range are one-line errors naming the field
// (--gravity 1e300, --ball-diameter 1e300, --ground-z -1e300 ran to the end before).
#include <gtest/gtest.h>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/trajectory_run.h"
#include "fieldvision/util/testing.h"

namespace fv::recon {
namespace {

TEST(TrajectoryLimits, OptionsOutOfRangeNameTheField) {
  const auto error_of = [](auto edit) {
    TrajectoryOptions o;
    edit(o);
    return testing::ErrorOf([&] { o.Check(); });
  };
  EXPECT_EQ(error_of([](TrajectoryOptions&) {}), "");
  EXPECT_NE(error_of([](TrajectoryOptions& o) { o.gravity_mps2 = 1e300; }).find("gravity_mps2"),
            std::string::npos);
  EXPECT_NE(error_of([](TrajectoryOptions& o) { o.ball_radius_m = 1e300; }).find("ball_radius_m"),
            std::string::npos);
  EXPECT_NE(error_of([](TrajectoryOptions& o) { o.ground_z_m = -1e300; }).find("ground_z_m"),
            std::string::npos);
  EXPECT_NE(error_of([](TrajectoryOptions& o) { o.noise_m = 1e300; }).find("noise_m"),
            std::string::npos);
}

TEST(TrajectoryLimits, JobValuesOutOfRangeNameTheField) {
  TrajectoryJob job;
  job.in_path = "BALL.csv";
  job.out_path = "FLIGHTS.json";
  EXPECT_EQ(testing::ErrorOf([&] { job.Check(); }), "");
  job.ball_mass_kg = 1e300;
  EXPECT_NE(testing::ErrorOf([&] { job.Check(); }).find("ball_mass_kg"), std::string::npos);
  job.ball_mass_kg = 0;
  job.ball_diameter_m = 1e300;
  EXPECT_NE(testing::ErrorOf([&] { job.Check(); }).find("ball_diameter_m"), std::string::npos);
}

}  // namespace
}  // namespace fv::recon
