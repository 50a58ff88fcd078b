#include "fieldvision/calib/rig_place.h"

#include <algorithm>
#include <iostream>

#include <gtest/gtest.h>

#include "fieldvision/calib/calib_testing.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/stats.h"

namespace fv::calib {
namespace {

using test_util::InRigFrame;
using test_util::WorstCentreErrorM;

// Sum of squared reprojection errors of the clicks through `cams`.
double SquaredErrorPx2(const std::vector<camera::Camera>& cams,
                       const std::vector<std::vector<PointCorrespondence>>& pts) {
  double sq = 0;
  for (size_t i = 0; i < cams.size(); ++i) {
    for (const auto& p : pts[i]) sq += (*cams[i].Project(p.p_world) - p.uv_px).squaredNorm();
  }
  return sq;
}

// The Cramer-Rao bound of a placement from clicks of `sigma_px` noise: the covariance of the 6
// parameters of a rigid move of the world, sigma^2 (J^T J)^-1 with J the clicks' Jacobian,
// carried to the points of the playing area (1 m grid, heights 0 and 1 m); the median of their
// standard deviations (the bound on FieldPositionErrorM's spread).
double FieldErrorBoundM(const std::vector<camera::Camera>& truth,
                        const std::vector<std::vector<PointCorrespondence>>& pts,
                        const field::FieldModel& field, double sigma_px) {
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  auto moved = [](const Vec6& d) {
    return geometry::Rigid3d::FromRvecTvec(d.head<3>(), d.tail<3>());
  };
  auto step = [](int k, double h) {
    Vec6 d = Vec6::Zero();
    d[k] = h;
    return d;
  };
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Zero();
  for (size_t c = 0; c < truth.size(); ++c) {
    for (const auto& p : pts[c]) {
      Eigen::Matrix<double, 2, 6> j;
      for (int k = 0; k < 6; ++k) {
        camera::Camera ca = truth[c], cb = truth[c];
        ca.cam_from_world = truth[c].cam_from_world * moved(step(k, 1e-6));
        cb.cam_from_world = truth[c].cam_from_world * moved(step(k, -1e-6));
        j.col(k) = (*ca.Project(p.p_world) - *cb.Project(p.p_world)) / 2e-6;
      }
      info += j.transpose() * j;
    }
  }
  const Eigen::Matrix<double, 6, 6> cov = sigma_px * sigma_px * info.inverse();
  std::vector<double> std_m;
  for (double x = -0.5 * field.length_m; x <= 0.5 * field.length_m + 1e-9; x += 1.0) {
    for (double y = -0.5 * field.width_m; y <= 0.5 * field.width_m + 1e-9; y += 1.0) {
      for (double z : {0.0, 1.0}) {
        const Eigen::Vector3d q(x, y, z);
        Eigen::Matrix<double, 3, 6> jq;
        for (int k = 0; k < 6; ++k) {
          jq.col(k) =
              (moved(step(k, 1e-6)).Inverse() * q - moved(step(k, -1e-6)).Inverse() * q) / 2e-6;
        }
        std_m.push_back(std::sqrt((jq * cov * jq.transpose()).trace()));
      }
    }
  }
  return util::NearestRankPercentile(std_m, 0.5);
}

// The demo rig (4 cameras at the corners of the RoboCup field, 1280x960) placed from 6 keypoint
// clicks with 1 px noise, all in one camera or 2 in each of three cameras.
TEST(RigPlace, SixClicksWithOnePixelNoisePlaceTheRig) {
  fv::testing::SeededRng rng(71);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const auto truth = test_util::PresetCameras("demo", 1);
  ASSERT_EQ(truth.size(), 4u);
  const auto rig = InRigFrame(truth);
  std::vector<double> one_cam, spread, field_one, field_spread, field_max_one, field_max_spread;
  std::vector<double> bound_one;
  double field_max = 0;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<std::vector<PointCorrespondence>> pts(4);
    pts[2] = test_util::ClickKeypoints(truth[2], field, 6, 1.0, rng);
    ASSERT_EQ(pts[2].size(), 6u);
    const RigPlacementResult a = PlaceRig(rig, pts);
    EXPECT_EQ(a.num_inliers, 6) << a.Summary();
    // The optimum: the placement fits the clicks at least as well as the truth does.
    EXPECT_LE(SquaredErrorPx2(a.cameras, pts), SquaredErrorPx2(truth, pts) * (1 + 1e-6));
    one_cam.push_back(WorstCentreErrorM(a.cameras, truth));
    field_one.push_back(test_util::FieldPositionErrorM(a.cameras, truth, field, &field_max));
    bound_one.push_back(FieldErrorBoundM(truth, pts, field, 1.0));
    field_max_one.push_back(field_max);

    std::vector<std::vector<PointCorrespondence>> spread_pts(4);
    for (int c : {0, 1, 3}) spread_pts[c] = test_util::ClickKeypoints(truth[c], field, 2, 1.0, rng);
    const RigPlacementResult b = PlaceRig(rig, spread_pts);
    EXPECT_EQ(b.start.rfind("all cameras", 0), 0u) << b.start;
    EXPECT_LE(SquaredErrorPx2(b.cameras, spread_pts),
              SquaredErrorPx2(truth, spread_pts) * (1 + 1e-6));
    spread.push_back(WorstCentreErrorM(b.cameras, truth));
    field_spread.push_back(test_util::FieldPositionErrorM(b.cameras, truth, field, &field_max));
    field_max_spread.push_back(field_max);
  }
  auto median = [](const std::vector<double>& v) { return util::NearestRankPercentile(v, 0.5); };
  auto max = [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); };
  std::cout << "points of the field (1 m grid, heights 0 and 1 m) as the placed rig puts them, "
               "over 20 placements: 6 clicks in one camera: median "
            << 1000 * median(field_one) << " mm (worst point: median "
            << 1000 * median(field_max_one) << " mm, max " << 1000 * max(field_max_one)
            << " mm); 2 clicks in each of 3 cameras: median " << 1000 * median(field_spread)
            << " mm (worst point: median " << 1000 * median(field_max_spread) << " mm, max "
            << 1000 * max(field_max_spread) << " mm); the Cramer-Rao bound of 6 clicks in one "
            << "camera: median point std " << 1000 * median(bound_one) << " mm\n";
  std::cout << "worst camera centre error over 20 placements: 6 clicks in one camera: median "
            << 1000 * median(one_cam) << " mm, max " << 1000 * max(one_cam)
            << " mm; 2 clicks in each of 3 cameras: median " << 1000 * median(spread) << " mm, max "
            << 1000 * max(spread) << " mm\n";
  // 1 px is about 2 cm on the ground at 20 m: six clicks place the rig within a few cm (the
  // optimum: checked above against the truth's own fit), not 1 cm.
  // The field itself (where the rig puts the ball) is placed better than the camera centres, but
  // not within 1 cm from 6 clicks of 1 px (median 18-21 mm over seeds 1-6, 27 mm with the clicks
  // spread over three cameras): no estimate can, the Cramer-Rao bound of these clicks is 20 mm
  // (median point std). The painted lines bring it to about a millimetre (rig_lines_test).
  EXPECT_LT(median(field_one), 0.035);
  // An efficient estimate: the field error is the bound's (a median distance vs a 3D std).
  EXPECT_LT(median(field_one), 1.5 * median(bound_one));
  EXPECT_LT(median(field_spread), 0.06);
  EXPECT_LT(median(one_cam), 0.06);
  EXPECT_LT(max(one_cam), 0.15);
  EXPECT_LT(median(spread), 0.10);
  // The worst of 20 placements from 2 clicks in each of 3 cameras, over seeds 1-200: at most
  // 0.31 m (the next 0.29, 0.26, 0.26 m).
  EXPECT_LT(max(spread), 0.35);
}

TEST(RigPlace, AGrossClickIsLeftOutAndCarryKeepsRelativePoses) {
  fv::testing::SeededRng rng(72);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const auto truth = test_util::PresetCameras("demo", 1);
  const auto rig = InRigFrame(truth);
  std::vector<std::vector<PointCorrespondence>> pts(4);
  pts[1] = test_util::ClickKeypoints(truth[1], field, 8, 0.5, rng);
  pts[1][3].uv_px += Eigen::Vector2d(60, -40);
  const RigPlacementResult r = PlaceRig(rig, pts);
  EXPECT_FALSE(r.points[1][3].inlier) << r.Summary();
  EXPECT_EQ(r.num_inliers, 7);
  EXPECT_LT(WorstCentreErrorM(r.cameras, truth), 0.1) << r.Summary();

  // Camera 3 moved: the others follow, relative poses unchanged.
  geometry::Rigid3d moved = truth[3].cam_from_world;
  moved.translation += Eigen::Vector3d(0.3, -0.2, 0.1);
  const auto carried = CarryRig(truth, 3, moved);
  EXPECT_LT((carried[3].cam_from_world.translation - moved.translation).norm(), 1e-9);
  for (int i = 0; i < 4; ++i) {
    const geometry::Rigid3d before = truth[i].cam_from_world * truth[0].cam_from_world.Inverse();
    const geometry::Rigid3d after = carried[i].cam_from_world * carried[0].cam_from_world.Inverse();
    EXPECT_LT((before.translation - after.translation).norm(), 1e-9);
    EXPECT_LT(geometry::RotationAngleBetween(before.rotation, after.rotation), 1e-9);
  }
}

TEST(RigPlace, TooFewOrUnusablePointsAreErrors) {
  const auto truth = test_util::PresetCameras("demo", 1);
  const auto rig = InRigFrame(truth);
  std::vector<std::vector<PointCorrespondence>> pts(4);
  EXPECT_THROW(PlaceRig(rig, pts), Error);
  pts[0].resize(3);
  for (auto& p : pts[0]) p.uv_px = Eigen::Vector2d(100, 100);
  EXPECT_THROW(PlaceRig(rig, pts), Error);
  EXPECT_THROW(PlaceRig(rig, {}), Error);
  std::vector<camera::Camera> no_pose = rig;
  no_pose[1].has_pose = false;
  EXPECT_THROW(PlaceRig(no_pose, std::vector<std::vector<PointCorrespondence>>(4)), Error);
}

}  // namespace
}  // namespace fv::calib
