#include "fieldvision/calib/extrinsics.h"

#include <algorithm>
#include <fstream>
#include <iostream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/calib/calib_testing.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/testing.h"

namespace fv::calib {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

using test_util::ClickKeypoints;

// A camera about 20 m from the field centre of the RoboCup MSL field, looking at it.
camera::Camera TwentyMetreCamera() {
  camera::Camera cam = camera::Camera::FromFov(1280, 960, 60.0);
  cam.distortion = {-0.05, 0.02, 0.0, 0.0, 0.0};
  cam.has_pose = true;
  cam.cam_from_world =
      geometry::Rigid3d::LookAt(Eigen::Vector3d(-15.0, -12.0, 7.0), Eigen::Vector3d::Zero());
  return cam;
}

TEST(Extrinsics, EightKeypointsWithOnePixelNoiseWithin5cmAt20m) {
  // 40 independent clicks of 8 keypoints with 1 px noise: the camera position error is a
  // random variable (the estimate is maximum likelihood; its spread is the geometry's), so we
  // check its median and 90th percentile.
  fv::testing::SeededRng rng(3);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const camera::Camera truth = TwentyMetreCamera();
  ASSERT_NEAR(truth.CentreInWorld().norm(), 20.4, 0.1);
  camera::Camera intrinsics = truth;
  intrinsics.has_pose = false;
  std::vector<double> errs_m;
  for (int trial = 0; trial < 40; ++trial) {
    const auto pts = ClickKeypoints(truth, field, 8, 1.0, rng);
    ASSERT_EQ(pts.size(), 8u);
    const ExtrinsicsResult r = EstimatePose(intrinsics, pts);
    errs_m.push_back((r.camera_position_m - truth.CentreInWorld()).norm());
    EXPECT_EQ(r.num_inliers, 8) << r.Summary();
    EXPECT_GT(r.rms_px, 0.1);  // the noise is there: a zero residual would be suspicious
    EXPECT_LT(r.rms_px, 2.5);
    for (const auto& p : r.points) {
      ASSERT_TRUE(p.err_mm.has_value());
      EXPECT_LT(*p.err_mm, 400.0) << p.name;  // grazing rays: a pixel spans decimetres
    }
  }
  const double median_m = util::NearestRankPercentile(errs_m, 0.5);
  const double p90_m = util::RankPercentile(errs_m, 0.9);
  EXPECT_LT(median_m, 0.05);
  EXPECT_LT(p90_m, 0.08);
  std::cout << "camera position error over 40 clicks: median " << 1000 * median_m
            << " mm, 90th percentile " << 1000 * p90_m << " mm\n";
}

TEST(Extrinsics, GrossOutlierIsRejected) {
  fv::testing::SeededRng rng(5);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const camera::Camera truth = TwentyMetreCamera();
  auto pts = ClickKeypoints(truth, field, 10, 0.5, rng);
  pts[3].uv_px += Eigen::Vector2d(60, -45);  // a point clicked at the wrong place
  camera::Camera intrinsics = truth;
  intrinsics.has_pose = false;
  const ExtrinsicsResult r = EstimatePose(intrinsics, pts);
  EXPECT_FALSE(r.points[3].inlier);
  EXPECT_EQ(r.num_inliers, 9);
  EXPECT_LT((r.camera_position_m - truth.CentreInWorld()).norm(), 0.1) << r.Summary();
}

TEST(Extrinsics, FewerThanFourPointsIsAnError) {
  const camera::Camera cam = TwentyMetreCamera();
  std::vector<PointCorrespondence> pts(3);
  for (int i = 0; i < 3; ++i) {
    pts[i].p_world = Eigen::Vector3d(i, i * i, 0);
    pts[i].uv_px = *cam.Project(pts[i].p_world);
  }
  EXPECT_THAT([&] { EstimatePose(cam, pts); }, ThrowsMessage<Error>(HasSubstr("only 3 points")));
}

TEST(Extrinsics, CollinearPointsAreAnError) {
  const camera::Camera cam = TwentyMetreCamera();
  std::vector<PointCorrespondence> pts;
  for (int i = 0; i < 6; ++i) {
    PointCorrespondence p;
    p.p_world = Eigen::Vector3d(-5 + 2 * i, 3, 0);
    p.uv_px = *cam.Project(p.p_world);
    pts.push_back(p);
  }
  EXPECT_THAT([&] { EstimatePose(cam, pts); }, ThrowsMessage<Error>(HasSubstr("one line")));
}

TEST(Extrinsics, ReadsNamedAndNumericPointFiles) {
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const std::string dir = fv::testing::TempDir();
  {
    std::ofstream f(dir + "/named.csv");
    f << "u,v,name\n100,200,centre_spot\n300.5,400,corner_left_bottom\n";
  }
  const auto named = ReadPointsCsv(dir + "/named.csv", &field);
  ASSERT_EQ(named.size(), 2u);
  EXPECT_EQ(named[1].p_world, field.FindKeypoint("corner_left_bottom")->position_m);
  EXPECT_DOUBLE_EQ(named[1].uv_px.x(), 300.5);
  {
    std::ofstream f(dir + "/xyz.csv");
    f << "u,v,x,y,z\n1,2,3,4,5\n";
  }
  const auto xyz = ReadPointsCsv(dir + "/xyz.csv", nullptr);
  ASSERT_EQ(xyz.size(), 1u);
  EXPECT_EQ(xyz[0].p_world, Eigen::Vector3d(3, 4, 5));
}

TEST(Extrinsics, UnknownKeypointNameIsAnErrorNamingIt) {
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const std::string path = fv::testing::TempDir() + "/bad.csv";
  {
    std::ofstream f(path);
    f << "u,v,name\n100,200,centre_spot\n300,400,centre_sport\n";
  }
  EXPECT_THAT(
      [&] { ReadPointsCsv(path, &field); },
      ThrowsMessage<Error>(::testing::AllOf(HasSubstr("centre_sport"), HasSubstr("bad.csv:3"),
                                            ::testing::Not(HasSubstr("\n")))));
}

TEST(Extrinsics, MissingColumnsAndNaNAreErrors) {
  const std::string dir = fv::testing::TempDir();
  {
    std::ofstream f(dir + "/cols.csv");
    f << "u,v,x\n1,2,3\n";
  }
  EXPECT_THROW(ReadPointsCsv(dir + "/cols.csv", nullptr), Error);
  {
    std::ofstream f(dir + "/nan.csv");
    f << "u,v,x,y,z\n1,2,nan,4,5\n";
  }
  EXPECT_THROW(ReadPointsCsv(dir + "/nan.csv", nullptr), Error);
  EXPECT_THROW(ReadPointsCsv(dir + "/missing.csv", nullptr), Error);
}

TEST(Extrinsics, APointOutsideTheImageIsAnErrorNamingItsLine) {
  const std::string path = fv::testing::TempDir() + "/outside.csv";
  {
    std::ofstream f(path);
    f << "u,v,x,y,z\n0,0,0,0,0\n1087.4,1919.4,1,0,0\n500,1528,2,0,0\n";
  }
  // Inside a 1088x1920 (portrait) frame, corners included.
  EXPECT_EQ(ReadPointsCsv(path, nullptr, 1088, 1920).size(), 3u);
  EXPECT_EQ(ReadPointsCsv(path, nullptr).size(), 3u);  // no size: no check
  // The same points with width and height swapped: the second lies below a 1088-high image.
  EXPECT_THAT([&] { ReadPointsCsv(path, nullptr, 1920, 1088); },
              ThrowsMessage<Error>(::testing::AllOf(HasSubstr("outside.csv:3"),
                                                    HasSubstr("outside the 1920x1088 image"),
                                                    HasSubstr("swapped"))));
  EXPECT_THAT([&] { ReadPointsCsv(path, nullptr, 640, 480); },
              ThrowsMessage<Error>(::testing::AllOf(HasSubstr("outside.csv:3"),
                                                    ::testing::Not(HasSubstr("swapped")))));
}

}  // namespace
}  // namespace fv::calib
