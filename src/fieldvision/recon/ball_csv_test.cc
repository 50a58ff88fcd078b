#include "fieldvision/recon/ball_csv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::recon {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(BallCsv, RowReadsTheColumnsTheTableHas) {
  const util::CsvTable full = util::CsvTable::Parse(
      "frame,time_s,x_m,y_m,z_m,n_cams,err_px\n7,0.28,1.5,-2,0.11,3,0.75\n", "BALL.csv");
  const BallSample s = ReadBallCsvRow(full, 0);
  EXPECT_EQ(s.frame, 7);
  EXPECT_DOUBLE_EQ(s.time_s, 0.28);
  EXPECT_EQ(s.ball_in_world, Eigen::Vector3d(1.5, -2, 0.11));
  EXPECT_EQ(s.n_cams, 3);
  EXPECT_DOUBLE_EQ(s.err_px, 0.75);
  // A truth file with only frame and position: the rest keeps BallSample's defaults.
  const BallSample t =
      ReadBallCsvRow(util::CsvTable::Parse("x_m,frame,z_m,y_m\n1,4,3,2\n", "t.csv"), 0);
  EXPECT_EQ(t.frame, 4);
  EXPECT_EQ(t.ball_in_world, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(t.n_cams, BallSample().n_cams);
  EXPECT_EQ(t.time_s, BallSample().time_s);
  EXPECT_THAT(
      [&] { ReadBallCsvRow(util::CsvTable::Parse("frame,x_m,y_m,z_m\n1,1,abc,3\n", "b.csv"), 0); },
      ThrowsMessage<Error>(HasSubstr("b.csv")));
}

TEST(BallCsv, WrittenTrackReadsBack) {
  std::vector<BallSample> samples(3);
  for (int i = 0; i < 3; ++i) {
    samples[i].frame = 10 + i;
    samples[i].time_s = 0.5 + 0.04 * i;
    samples[i].ball_in_world = Eigen::Vector3d(i, -0.25 * i, 0.11 + i);
    samples[i].n_cams = 2 + i;
    samples[i].err_px = 0.125 * i;
  }
  const std::string path = testing::TempDir() + "/ball_csv_roundtrip.csv";
  WriteBallTrack(path, samples);
  const util::CsvTable table = util::CsvTable::Read(path);
  for (const auto& c : BallCsvColumns()) EXPECT_TRUE(table.Has(c)) << c;
  const BallTrackFile back = ReadBallTrack(path);
  EXPECT_EQ(back.layout, "ball");
  ASSERT_EQ(back.samples.size(), samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    EXPECT_EQ(back.samples[i].frame, samples[i].frame);
    EXPECT_NEAR(back.samples[i].time_s, samples[i].time_s, 1e-9);
    EXPECT_LT((back.samples[i].ball_in_world - samples[i].ball_in_world).norm(), 1e-9);
    EXPECT_EQ(back.samples[i].n_cams, samples[i].n_cams);
    EXPECT_NEAR(back.samples[i].err_px, samples[i].err_px, 1e-9);
  }
}

}  // namespace
}  // namespace fv::recon
