#include "fieldvision/recon/trajectory_io.h"

#include <fstream>
#include <iostream>

#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::recon {
namespace {

const char* const kHeader = "frame,time_s,x_m,y_m,z_m,n_cams,err_px\n";

std::string ErrorOf(const std::string& text) {
  try {
    ParseBallTrack(util::CsvTable::Parse(text, "BALL.csv"));
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Seconds and metres: a noisy 240 Hz kick (30 cm of noise, 150 m/s from one row to the next)
// reads; the same track in millimetres, or its times in milliseconds, is named.
TEST(TrajectoryIo, TracksInOtherUnitsAreNamedNotFitted) {
  const uint64_t seed = testing::TestSeed(5);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  std::string metres = kHeader, millimetres = kHeader, milliseconds = kHeader;
  for (int i = 0; i < 240; ++i) {
    const double t = i / 240.0;
    const Eigen::Vector3d p(-5 + 12 * t + rng.Normal(0, 0.3), 2 * t + rng.Normal(0, 0.3),
                            0.11 + 6 * t - 4.9 * t * t + rng.Normal(0, 0.3));
    metres += fmt::format("{},{},{},{},{},2,0.5\n", i, t, p.x(), p.y(), p.z());
    millimetres +=
        fmt::format("{},{},{},{},{},2,0.5\n", i, t, 1e3 * p.x(), 1e3 * p.y(), 1e3 * p.z());
    milliseconds += fmt::format("{},{},{},{},{},2,0.5\n", i, 1e3 * t, p.x(), p.y(), p.z());
  }
  EXPECT_EQ(ErrorOf(metres), "");
  EXPECT_NE(ErrorOf(millimetres).find("are its positions in metres"), std::string::npos);
  EXPECT_NE(ErrorOf(milliseconds).find("are its times in seconds"), std::string::npos);
}

TEST(TrajectoryIo, MissingColumnsAreNamed) {
  const std::string e = ErrorOf("frame,time_s,x_m,y_m,n_cams\n0,0,1,2,2\n");
  EXPECT_NE(e.find("z_m"), std::string::npos) << e;
  EXPECT_NE(e.find("BALL.csv"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << "one line: " << e;
  EXPECT_NE(ErrorOf("a,b,c\n1,2,3\n").find("unknown columns"), std::string::npos);
  EXPECT_NE(ErrorOf("").find("empty"), std::string::npos);
}

TEST(TrajectoryIo, BadRowsAreNamedAndSkipped) {
  const std::string text = std::string(kHeader) +
                           "0,0.00,1,2,3,2,0.5\n"
                           "1,0.02,nan,2,3,2,0.5\n"  // NaN
                           "2,0.04,1,2,abc,2,0.5\n"  // not a number
                           "3,0.00,1,2,3,2,0.5\n"    // duplicate time
                           "4,0.06,1,2,3,2,0.5\n"
                           "5,0.05,1,2,3,2,0.5\n"    // out of order
                           "6,0.08,1,2,inf,2,0.5\n"  // infinite
                           "7,0.10,1,2,3,2,\n";      // empty err_px
  const BallTrackFile f = ParseBallTrack(util::CsvTable::Parse(text, "BALL.csv"));
  ASSERT_EQ(f.samples.size(), 2u);
  EXPECT_EQ(f.samples[0].frame, 0);
  EXPECT_EQ(f.samples[1].frame, 4);
  ASSERT_EQ(f.skipped.size(), 6u);
  EXPECT_NE(f.skipped[0].find("BALL.csv:3"), std::string::npos) << f.skipped[0];
  EXPECT_NE(f.skipped[2].find("repeats"), std::string::npos) << f.skipped[2];
  EXPECT_NE(f.skipped[3].find("is before"), std::string::npos) << f.skipped[3];
}

TEST(TrajectoryIo, ReversedFileIsAnErrorNotASilentTruncation) {
  std::string text = kHeader;
  for (int i = 9; i >= 0; --i) {
    text += std::to_string(i) + "," + std::to_string(i * 0.02) + ",1,2,3,2,0\n";
  }
  const std::string e = ErrorOf(text);
  EXPECT_NE(e.find("not increasing"), std::string::npos) << e;
  EXPECT_NE(ErrorOf(std::string(kHeader) + "0,nan,1,2,3,2,0\n").find("no valid rows"),
            std::string::npos);
}

TEST(TrajectoryIo, Tt3dLayoutAndRoundTrip) {
  const BallTrackFile f = ParseBallTrack(util::CsvTable::Parse(
      "Timestamp,X,Y,Z\n12.0,0.1,0.2,0.3\n12.005,0.11,0.19,0.31\n", "tt.csv"));
  EXPECT_EQ(f.layout, "tt3d");
  ASSERT_EQ(f.samples.size(), 2u);
  EXPECT_DOUBLE_EQ(f.samples[1].ball_in_world.z(), 0.31);
  const std::string path = testing::TempDir() + "/ball.csv";
  WriteBallTrack(path, f.samples);
  const BallTrackFile g = ReadBallTrack(path);
  EXPECT_EQ(g.layout, "ball");
  ASSERT_EQ(g.samples.size(), 2u);
  EXPECT_NEAR(g.samples[1].time_s, 12.005, 1e-9);
  EXPECT_NEAR(g.samples[0].ball_in_world.y(), 0.2, 1e-9);
  EXPECT_THROW(ReadBallTrack(testing::TempDir() + "/missing.csv"), Error);
}

}  // namespace
}  // namespace fv::recon
