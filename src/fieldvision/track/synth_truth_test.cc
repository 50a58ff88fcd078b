#include "fieldvision/track/synth_truth.h"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::track {
namespace {

using ::testing::HasSubstr;

TEST(SynthTruth, PeopleTruthWithPositionsBesideIt) {
  const std::string dir = fv::testing::TempDir();
  std::ofstream(dir + "/players_2d.csv")
      << "frame,cam,id,bb_left,bb_top,bb_width,bb_height,visible_fraction\n"
      << "0,side,1,10,20,30,90,1.0\n"
      << "0,side,2,100,20,30,90,0.1\n"  // hardly visible: left out
      << "1,side,1,12,20,30,90,0.8\n";
  std::ofstream(dir + "/players.csv") << "frame,time_s,id,team,x_m,y_m\n"
                                      << "0,0.0,1,0,-4.5,2.0\n"
                                      << "1,0.04,1,0,-4.4,2.0\n";
  const std::string path = dir + "/players_2d.csv";
  ASSERT_TRUE(IsSynthPeopleTruth(path));
  const std::vector<TrackRow> rows = ReadSynthPeopleTruth(path);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].frame, 1);  // TRACKS.csv numbers frames from 1
  EXPECT_EQ(rows[1].frame, 2);
  EXPECT_EQ(rows[0].id, 1);
  EXPECT_DOUBLE_EQ(rows[1].box.x, 12);
  EXPECT_DOUBLE_EQ(rows[1].visibility, 0.8);
  ASSERT_TRUE(rows[1].x_m && rows[1].y_m && rows[1].time_s);
  EXPECT_DOUBLE_EQ(*rows[1].x_m, -4.4);
  EXPECT_DOUBLE_EQ(*rows[1].time_s, 0.04);
  EXPECT_EQ(ReadSynthPeopleTruth(path, "", 0.0).size(), 3u);
  EXPECT_FALSE(IsSynthPeopleTruth(dir + "/players.csv"));
}

TEST(SynthTruth, SeveralCamerasAndBadRowsAreNamed) {
  const std::string dir = fv::testing::TempDir();
  const std::string path = dir + "/players_2d.csv";
  std::ofstream(path) << "frame,cam,id,bb_left,bb_top,bb_width,bb_height,visible_fraction\n"
                      << "0,left,1,10,20,30,90,1.0\n"
                      << "0,right,1,10,20,30,90,1.0\n";
  EXPECT_THAT(fv::testing::ErrorOf([&] { ReadSynthPeopleTruth(path); }),
              HasSubstr("cameras left, right: name one (--gt-cam)"));
  EXPECT_EQ(ReadSynthPeopleTruth(path, "right").size(), 1u);
  EXPECT_THAT(fv::testing::ErrorOf([&] { ReadSynthPeopleTruth(path, "top"); }),
              HasSubstr("no camera 'top'"));
  std::ofstream(path) << "frame,cam,id,bb_left,bb_top,bb_width,bb_height,visible_fraction\n"
                      << "0,side,1,10,20,-30,90,1.0\n";
  EXPECT_THAT(fv::testing::ErrorOf([&] { ReadSynthPeopleTruth(path); }),
              HasSubstr("players_2d.csv:2"));
}

}  // namespace
}  // namespace fv::track
