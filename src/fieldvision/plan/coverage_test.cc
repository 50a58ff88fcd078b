#include "fieldvision/plan/coverage.h"

#include <cmath>
#include <cstdio>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "fieldvision/field/field.h"
#include "fieldvision/plan/rig_json.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::plan {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// A camera looking straight down from `height_m` above the plane z = plane_z whose image covers
// exactly [cx - sx/2, cx + sx/2) x (cy - sy/2, cy + sy/2] of that plane.
camera::Camera OverheadCamera(const std::string& name, Eigen::Vector2d centre, double size_x_m,
                              double size_y_m, double plane_z, double height_m, double px_per_m) {
  camera::Camera c;
  c.name = name;
  c.width = static_cast<int>(std::lround(size_x_m * px_per_m));
  c.height = static_cast<int>(std::lround(size_y_m * px_per_m));
  c.fx = c.fy = px_per_m * height_m;
  c.cx = 0.5 * (c.width - 1);
  c.cy = 0.5 * (c.height - 1);
  Eigen::Matrix3d rot;
  rot << 1, 0, 0, 0, -1, 0, 0, 0, -1;  // image x = world x, image y = -world y, looking down
  const Eigen::Vector3d eye(centre.x(), centre.y(), plane_z + height_m);
  c.cam_from_world = geometry::Rigid3d{rot, -rot * eye};
  c.has_pose = true;
  return c;
}

TEST(CoverageTest, OverheadFootprintsGiveExactFractions) {
  const field::FieldModel field = field::BuiltinField("robocup-msl");  // 18 x 12 m
  CoverageOptions o;
  o.grid_step_m = 0.25;
  o.height_above_m = 0;
  o.min_ball_px = 0;
  const double z = 0.5 * o.ball_diameter_m;
  // A sees the half x < 0, B the half y < 0, C the quarter x < 0, y < 0; D sees x > 0, y > 0
  // from a different height and resolution. By construction each quadrant has a known count.
  const std::vector<camera::Camera> cams = {OverheadCamera("A", {-4.5, 0}, 9, 12, z, 6.0, 40),
                                            OverheadCamera("B", {0, -3}, 18, 6, z, 9.0, 30),
                                            OverheadCamera("C", {-4.5, -3}, 9, 6, z, 3.0, 50),
                                            OverheadCamera("D", {4.5, 3}, 9, 6, z, 12.0, 20)};
  const CoverageResult r = EvaluateCoverage(cams, field, o);
  ASSERT_EQ(r.layers.size(), 1u);
  const CoverageLayer& L = r.layers[0];
  EXPECT_EQ(L.nx, 72);
  EXPECT_EQ(L.ny, 48);
  for (int j = 0; j < L.ny; ++j) {
    for (int i = 0; i < L.nx; ++i) {
      const Eigen::Vector3d p = L.CellCentre(i, j);
      const int expected = (p.x() < 0 && p.y() < 0) ? 3 : 1;
      ASSERT_EQ(L.count[j * L.nx + i], expected) << "cell " << p.transpose();
    }
  }
  // Quadrants: (-,-) 3 cameras, (-,+) A, (+,-) B, (+,+) D.
  ASSERT_EQ(L.fraction_exactly.size(), 5u);
  EXPECT_DOUBLE_EQ(L.fraction_exactly[0], 0.0);
  EXPECT_DOUBLE_EQ(L.fraction_exactly[1], 0.75);
  EXPECT_DOUBLE_EQ(L.fraction_exactly[2], 0.0);
  EXPECT_DOUBLE_EQ(L.fraction_exactly[3], 0.25);
  EXPECT_DOUBLE_EQ(L.fraction_exactly[4], 0.0);
  EXPECT_DOUBLE_EQ(L.fraction_at_least_2, 0.25);

  // Without D, the quadrant x > 0, y > 0 is seen by none.
  const CoverageResult r3 = EvaluateCoverage({cams[0], cams[1], cams[2]}, field, o);
  EXPECT_DOUBLE_EQ(r3.layers[0].fraction_exactly[0], 0.25);
  EXPECT_DOUBLE_EQ(r3.layers[0].fraction_exactly[1], 0.5);
  EXPECT_DOUBLE_EQ(r3.layers[0].fraction_exactly[2], 0.0);
  EXPECT_DOUBLE_EQ(r3.layers[0].fraction_exactly[3], 0.25);
}

TEST(CoverageTest, RaisedLayerShrinksOverheadFootprint) {
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  CoverageOptions o;
  o.grid_step_m = 0.25;
  o.height_above_m = 2.0;
  o.min_ball_px = 0;
  const double z = 0.5 * o.ball_diameter_m;
  // From 8 m above the ball the footprint is 18 x 12 m; 2 m higher it is 3/4 of that: the cells
  // with |x| < 6.75 and |y| < 4.5, i.e. 54 x 36 of the 72 x 48 cells.
  const camera::Camera cam = OverheadCamera("top", {0, 0}, 18, 12, z, 8.0, 40);
  const CoverageResult r = EvaluateCoverage({cam}, field, o);
  ASSERT_EQ(r.layers.size(), 2u);
  EXPECT_DOUBLE_EQ(r.layers[0].fraction_exactly[1], 1.0);
  EXPECT_NEAR(r.layers[1].height_m, z + 2.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.layers[1].fraction_exactly[1], (54.0 * 36.0) / (72.0 * 48.0));
}

// The ball's image is f * D / depth pixels wide at its narrowest (depth along the optical axis,
// not the distance: a sphere off the axis images larger). From straight above every ground point
// is 5 m deep: with a limit just under 100 D px every cell the camera sees counts, just over it
// none (by the distance, only those within a radius of the nadir counted).
TEST(CoverageTest, BallTooSmallBeyondMaximumDepth) {
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  CoverageOptions o;
  o.grid_step_m = 0.5;
  o.height_above_m = 0;
  const double z = 0.5 * o.ball_diameter_m;
  const camera::Camera cam = OverheadCamera("top", {0, 0}, 18, 12, z, 5.0, 100);
  const double width_px = 100.0 * o.ball_diameter_m;  // f D / 5 m, f = 500 px
  o.min_ball_px = 0.99 * width_px;
  const CoverageLayer seen = EvaluateCoverage({cam}, field, o).layers[0];
  o.min_ball_px = 0;
  const CoverageLayer all = EvaluateCoverage({cam}, field, o).layers[0];
  EXPECT_GT(all.fraction_exactly[1], 0.5);
  EXPECT_DOUBLE_EQ(seen.fraction_exactly[1], all.fraction_exactly[1]);
  o.min_ball_px = 1.01 * width_px;
  EXPECT_DOUBLE_EQ(EvaluateCoverage({cam}, field, o).layers[0].fraction_exactly[1], 0.0);
}

// A barrel lens shrinks the ball near the image border (most along the radius): with the
// pinhole width just above the limit, the centre still sees it and the border does not.
TEST(CoverageTest, BarrelDistortionShrinksTheBallNearTheBorder) {
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  CoverageOptions o;
  const double z = 0.5 * o.ball_diameter_m;
  camera::Camera cam = OverheadCamera("top", {0, 0}, 18, 12, z, 5.0, 100);
  const double width_px = 100.0 * o.ball_diameter_m;  // f D / 5 m, f = 500 px
  o.min_ball_px = 0.95 * width_px;
  const Eigen::Vector3d centre(0, 0, z), border(8.0, 0, z);  // x/z 1.6 at the border
  EXPECT_TRUE(SeesPoint(cam, centre, o));
  EXPECT_TRUE(SeesPoint(cam, border, o));
  cam.distortion = {-0.02, 0, 0, 0, 0};  // 1 + 3 k1 r^2 = 0.85 at r = 1.6
  ASSERT_TRUE(cam.InImage(*cam.Project(border)));
  EXPECT_TRUE(SeesPoint(cam, centre, o));
  EXPECT_FALSE(SeesPoint(cam, border, o));
}

TEST(CoverageTest, BestPairAngleIsClosestTo90) {
  fv::testing::SeededRng rng(11);
  const Eigen::Vector3d p(rng.Uniform(-5, 5), rng.Uniform(-3, 3), 0.11);
  // Cameras along directions at 10, 40 and 140 degrees in a tilted plane: pair angles 30, 130
  // and 100 degrees; the best is 100.
  std::vector<camera::Camera> cams;
  for (double deg : {10.0, 40.0, 140.0}) {
    const double t = deg * M_PI / 180;
    const Eigen::Vector3d dir(std::cos(t), std::sin(t) * std::cos(0.5),
                              std::sin(t) * std::sin(0.5));
    cams.push_back(MakeAimedCamera("c", 640, 480, 60, p + rng.Uniform(6, 15) * dir, p));
  }
  EXPECT_NEAR(RayAngleDeg(cams[0].CentreInWorld(), cams[2].CentreInWorld(), p), 130.0, 1e-9);
  field::FieldModel field = field::BuiltinField("robocup-msl");
  CoverageOptions o;
  o.height_above_m = 0;
  o.min_ball_px = 0;
  o.grid_step_m = 0.1;
  // A one-cell "field" centred on p is awkward; evaluate the pair logic through a tiny field.
  field.length_m = 0.1;
  field.width_m = 0.1;
  for (auto& c : cams) {
    // Shift the world so that p sits at the single cell's centre (0, 0, z).
    c.cam_from_world.translation += c.cam_from_world.rotation * Eigen::Vector3d(p.x(), p.y(), 0);
  }
  const CoverageResult r = EvaluateCoverage(cams, field, o);
  ASSERT_EQ(r.layers[0].size(), 1u);
  EXPECT_EQ(r.layers[0].count[0], 3);
  EXPECT_NEAR(r.layers[0].best_angle_deg[0], 100.0, 1e-6);
}

// Linear least squares on normalized rays, then Gauss-Newton on the reprojection error.
Eigen::Vector3d Triangulate(const std::vector<camera::Camera>& cams,
                            const std::vector<Eigen::Vector2d>& uv) {
  Eigen::MatrixXd a(2 * cams.size(), 3);
  Eigen::VectorXd b(2 * cams.size());
  for (size_t i = 0; i < cams.size(); ++i) {
    const Eigen::Vector2d xn = *cams[i].Undistort(uv[i]);
    const Eigen::Matrix3d& r = cams[i].cam_from_world.rotation;
    const Eigen::Vector3d& t = cams[i].cam_from_world.translation;
    a.row(2 * i) = xn.x() * r.row(2) - r.row(0);
    a.row(2 * i + 1) = xn.y() * r.row(2) - r.row(1);
    b(2 * i) = t(0) - xn.x() * t(2);
    b(2 * i + 1) = t(1) - xn.y() * t(2);
  }
  Eigen::Vector3d x = a.colPivHouseholderQr().solve(b);
  for (int iter = 0; iter < 10; ++iter) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < cams.size(); ++i) {
      const auto j = ProjectionJacobian(cams[i], x);
      const auto proj = cams[i].Project(x);
      if (!j || !proj) return x;
      jtj += j->transpose() * *j;
      jtr += j->transpose() * (*proj - uv[i]);
    }
    const Eigen::Vector3d step = jtj.ldlt().solve(jtr);
    x -= step;
    if (step.norm() < 1e-12) break;
  }
  return x;
}

TEST(CoverageTest, ExpectedErrorMatchesMonteCarloTriangulation) {
  fv::testing::SeededRng rng(5);
  const double sigma_px = 1.5;
  for (int trial = 0; trial < 6; ++trial) {
    // 2 to 4 cameras around the field at 3-8 m, aimed near the point, some with distortion.
    const Eigen::Vector3d p(rng.Uniform(-8, 8), rng.Uniform(-5, 5), rng.Uniform(0.11, 2.0));
    const int n = 2 + trial % 3;
    std::vector<camera::Camera> cams;
    std::vector<const camera::Camera*> ptrs;
    for (int k = 0; k < n; ++k) {
      // Headings spread around the point so that no two rays are nearly parallel.
      const double heading = 2 * M_PI * k / n + rng.Uniform(-0.4, 0.4);
      const double range = rng.Uniform(8, 25);
      const Eigen::Vector3d eye =
          p + Eigen::Vector3d(range * std::cos(heading), range * std::sin(heading), 0) +
          Eigen::Vector3d(0, 0, rng.Uniform(3, 8) - p.z());
      const Eigen::Vector3d aim = p + Eigen::Vector3d(rng.Uniform(-2, 2), rng.Uniform(-2, 2), 0);
      camera::Camera c = MakeAimedCamera("c", 1280, 960, rng.Uniform(50, 90), eye, aim);
      if (k % 2 == 1) c.distortion = {rng.Uniform(-0.2, 0.05), rng.Uniform(0, 0.05), 0, 0, 0};
      cams.push_back(c);
    }
    ptrs.reserve(cams.size());
    for (const auto& c : cams) ptrs.push_back(&c);
    const auto cov = TriangulationCovariance(ptrs, p, sigma_px);
    ASSERT_TRUE(cov.has_value()) << "trial " << trial;
    const double predicted = std::sqrt(cov->trace());
    std::vector<Eigen::Vector2d> clean;
    for (const auto& c : cams) {
      const auto uv = c.Project(p);
      ASSERT_TRUE(uv && c.InImage(*uv)) << "trial " << trial;
      clean.push_back(*uv);
    }
    const int samples = 3000;
    double sum_sq = 0;
    for (int s = 0; s < samples; ++s) {
      std::vector<Eigen::Vector2d> noisy = clean;
      for (auto& uv : noisy) {
        uv += Eigen::Vector2d(rng.Normal(0, sigma_px), rng.Normal(0, sigma_px));
      }
      sum_sq += (Triangulate(cams, noisy) - p).squaredNorm();
    }
    const double measured = std::sqrt(sum_sq / samples);
    std::printf("  %d cameras: expected RMS 3D error %.2f mm, Monte Carlo %.2f mm (ratio %.3f)\n",
                n, 1000 * predicted, 1000 * measured, predicted / measured);
    EXPECT_NEAR(predicted / measured, 1.0, 0.10)
        << "trial " << trial << ": " << n << " cameras, predicted " << predicted * 1000
        << " mm, Monte Carlo " << measured * 1000 << " mm";
  }
}

TEST(CoverageTest, ProjectionJacobianMatchesFiniteDifferences) {
  fv::testing::SeededRng rng(9);
  for (int trial = 0; trial < 10; ++trial) {
    camera::Camera c =
        MakeAimedCamera("c", 1280, 960, rng.Uniform(40, 100),
                        {rng.Uniform(-12, 12), rng.Uniform(-8, -7), rng.Uniform(2, 8)},
                        {rng.Uniform(-3, 3), rng.Uniform(-2, 2), 0});
    if (trial % 2) c.distortion = {rng.Uniform(-0.3, 0.1), rng.Uniform(-0.05, 0.05), 0.001, 0, 0};
    const Eigen::Vector3d p(rng.Uniform(-4, 4), rng.Uniform(-3, 3), rng.Uniform(0, 2));
    const auto j = ProjectionJacobian(c, p);
    ASSERT_TRUE(j.has_value());
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-6;
      const Eigen::Vector3d dp = Eigen::Vector3d::Unit(k) * h;
      const Eigen::Vector2d fd = (*c.Project(p + dp) - *c.Project(p - dp)) / (2 * h);
      EXPECT_NEAR((fd - j->col(k)).norm(), 0, 1e-5 * (1 + fd.norm())) << "trial " << trial;
    }
  }
}

TEST(CoverageTest, OneCameraOrParallelRaysGiveNoError) {
  const Eigen::Vector3d p(1, 2, 0.11);
  const camera::Camera a = MakeAimedCamera("a", 640, 480, 60, {10, 2, 4}, p);
  EXPECT_FALSE(TriangulationCovariance({&a}, p, 1.0).has_value());
  // Two cameras on the same ray: the depth is not observable.
  const camera::Camera b = MakeAimedCamera("b", 640, 480, 60, p + 0.5 * (a.CentreInWorld() - p), p);
  EXPECT_FALSE(TriangulationCovariance({&a, &b}, p, 1.0).has_value());
}

TEST(CoverageTest, OptionsCheckNamesTheField) {
  CoverageOptions o;
  o.grid_step_m = 0;
  EXPECT_THAT([&] { o.Check(); }, ThrowsMessage<Error>(HasSubstr("grid_step_m")));
  o = CoverageOptions();
  o.good_angle_min_deg = 130;
  EXPECT_THROW(o.Check(), Error);
  o = CoverageOptions();
  o.pixel_noise_px = NAN;
  EXPECT_THROW(o.Check(), Error);
}

}  // namespace
}  // namespace fv::plan
