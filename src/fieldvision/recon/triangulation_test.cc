#include "fieldvision/recon/triangulation.h"

#include <cmath>
#include <iostream>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::recon {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// Four cameras at the corners of an 18 x 12 m field, 6 m high, looking at the centre.
std::vector<camera::Camera> CornerCameras(util::Rng* rng = nullptr) {
  std::vector<camera::Camera> cams;
  const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (int i = 0; i < 4; ++i) {
    camera::Camera c = camera::Camera::FromFov(1280, 960, 75);
    c.name = "cam" + std::to_string(i);
    if (rng) c.distortion = {rng->Uniform(-0.2, 0.0), rng->Uniform(0, 0.05), 0, 0, 0};
    const Eigen::Vector3d eye(sx[i] * 11.0, sy[i] * 8.0, 6.0);
    c.cam_from_world = geometry::Rigid3d::LookAt(eye, Eigen::Vector3d(0, 0, 0));
    c.has_pose = true;
    cams.push_back(c);
  }
  return cams;
}

BallObservation Observe(const camera::Camera& cam, const Eigen::Vector3d& p, double radius_m,
                        double sigma_px, util::Rng* rng) {
  auto uv = PredictBallCentre(cam, p, radius_m);
  EXPECT_TRUE(uv.has_value());
  BallObservation o;
  o.centre_px = *uv;
  if (rng && sigma_px > 0) {
    o.centre_px += Eigen::Vector2d(rng->Normal(0, sigma_px), rng->Normal(0, sigma_px));
  }
  o.sigma_px = sigma_px > 0 ? sigma_px : 1.0;
  return o;
}

Eigen::Vector3d RandomBall(util::Rng& rng) {
  return {rng.Uniform(-8, 8), rng.Uniform(-5, 5), rng.Uniform(0.11, 3.0)};
}

TEST(ClosestPointOfRays, IntersectingAndSkewRays) {
  testing::SeededRng rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d p(rng.Uniform(-5, 5), rng.Uniform(-5, 5), rng.Uniform(0, 3));
    const Eigen::Vector3d oa(rng.Uniform(-20, -10), rng.Uniform(-5, 5), rng.Uniform(2, 8));
    const Eigen::Vector3d ob(rng.Uniform(10, 20), rng.Uniform(-5, 5), rng.Uniform(2, 8));
    // Offset the second ray sideways by a known gap, perpendicular to both directions.
    const Eigen::Vector3d da = (p - oa).normalized(), db = (p - ob).normalized();
    const Eigen::Vector3d n = da.cross(db).normalized();
    const double gap = rng.Uniform(0, 0.5);
    const RayPairResult r = ClosestPointOfRays({oa, da}, {ob + gap * n, 3.0 * db});
    ASSERT_TRUE(r.ok());
    EXPECT_NEAR(r.gap_m, gap, 1e-9);
    EXPECT_LT((r.midpoint - (p + 0.5 * gap * n)).norm(), 1e-9);
    EXPECT_NEAR(r.s_a, (p - oa).norm(), 1e-9);
    EXPECT_NEAR(r.s_b, (p - ob).norm() / 3.0, 1e-9);  // in units of the given direction
  }
}

TEST(ClosestPointOfRays, ParallelRaysAreAValue) {
  const geometry::Ray3d a{{0, 0, 0}, {1, 0, 0}};
  const geometry::Ray3d b{{0, 2, 0}, {1, 0, 0}};
  const RayPairResult r = ClosestPointOfRays(a, b);
  EXPECT_EQ(r.status, RayPairStatus::kParallel);
  EXPECT_NEAR(r.gap_m, 2.0, 1e-12);
  // Anti-parallel is parallel too.
  EXPECT_EQ(ClosestPointOfRays(a, {{0, 2, 0}, {-1, 0, 0}}).status, RayPairStatus::kParallel);
  // A zero direction gives no point rather than NaN.
  EXPECT_EQ(ClosestPointOfRays(a, {{0, 2, 0}, {0, 0, 0}}).status, RayPairStatus::kParallel);
  EXPECT_THROW(ClosestPointOfRays(a, {{0, NAN, 0}, {1, 0, 0}}), Error);
}

TEST(ClosestPointOfRays, NearParallelRaysMeetFarAway) {
  // Two rays 1 m apart converging at 0.05 degrees meet about 1146 m away.
  const double angle = 0.05 * M_PI / 180.0;
  const geometry::Ray3d a{{0, 0, 0}, {1, 0, 0}};
  const geometry::Ray3d b{{0, 1, 0}, {std::cos(angle), -std::sin(angle), 0}};
  const RayPairResult r = ClosestPointOfRays(a, b);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r.midpoint.x(), 1.0 / std::tan(angle), 1e-3);
  EXPECT_NEAR(r.midpoint.y(), 0.0, 1e-6);
  EXPECT_NEAR(r.gap_m, 0.0, 1e-6);
  EXPECT_NEAR(r.angle_deg, 0.05, 1e-9);
  // Below the threshold it is reported as parallel.
  EXPECT_EQ(ClosestPointOfRays(a, b, 0.1).status, RayPairStatus::kParallel);
}

TEST(ClosestPointOfRays, PointBehindARayIsFlagged) {
  // Rays pointing away from each other: the closest point lies behind both origins.
  const RayPairResult r = ClosestPointOfRays({{-1, 0, 0}, {-1, 0.1, 0}}, {{1, 0, 0}, {1, 0.1, 0}});
  EXPECT_EQ(r.status, RayPairStatus::kBehind);
}

TEST(Triangulation, LinearIsExactWithoutNoise) {
  testing::SeededRng rng(12);
  const auto cams = CornerCameras(&rng);
  for (int trial = 0; trial < 30; ++trial) {
    const Eigen::Vector3d p = RandomBall(rng);
    std::vector<View> views;
    views.reserve(4);
    for (int c = 0; c < 4; ++c) views.push_back({c, Observe(cams[c], p, 0.0, 0, nullptr)});
    const auto x = TriangulateLinear(cams, views);
    ASSERT_TRUE(x.has_value());
    EXPECT_LT((*x - p).norm(), 1e-6);
  }
}

TEST(Triangulation, RefinedPointAndCovarianceMatchTheNoise) {
  testing::SeededRng rng(13);
  const auto cams = CornerCameras(&rng);
  TriangulationOptions opt;
  opt.outline_centre = true;
  // Normalized squared errors e^T C^-1 e follow chi-square(3): mean 3.
  double sum_chi2 = 0, sum_err = 0;
  const int trials = 200;
  for (int trial = 0; trial < trials; ++trial) {
    const Eigen::Vector3d p = RandomBall(rng);
    std::vector<View> views;
    for (int c = 0; c < 4; ++c) {
      const double sigma = rng.Uniform(0.2, 1.0);
      views.push_back({c, Observe(cams[c], p, opt.ball_radius_m, sigma, &rng)});
    }
    const TriangulationResult r = TriangulatePoint(cams, views, opt);
    ASSERT_TRUE(r.ok()) << ToString(r.status);
    ASSERT_EQ(r.num_views(), 4);
    EXPECT_GE(r.iterations, 1);
    const Eigen::Vector3d e = r.point_world - p;
    sum_chi2 += e.dot(r.covariance.inverse() * e);
    sum_err += e.norm();
    for (const auto& v : r.views) EXPECT_LT(v.err_px, 5.0);
  }
  EXPECT_NEAR(sum_chi2 / trials, 3.0, 0.6);
  EXPECT_LT(sum_err / trials, 0.02);
}

// One of four cameras fits a circle to part of the ball only (`shrink` of its radius, its centre
// off by the rest): its radius gives it away and its weight drops, the point moves far less than
// with every view weighted alike (radius_sigma_factor 0). Mean errors (m) over 100 trials.
struct PartialDiscErrors {
  double weighted = 0, unweighted = 0, clean = 0;
};
PartialDiscErrors PartialDisc(double shrink, util::Rng* rng) {
  const auto cams = CornerCameras(rng);
  TriangulationOptions on;
  TriangulationOptions off;
  off.radius_sigma_factor = 0;
  PartialDiscErrors e;
  const int trials = 100;
  for (int trial = 0; trial < trials; ++trial) {
    const Eigen::Vector3d p = RandomBall(*rng);
    std::vector<View> views;
    for (int c = 0; c < 4; ++c) {
      BallObservation o = Observe(cams[c], p, on.ball_radius_m, 0.3, rng);
      const double depth = (cams[c].cam_from_world * p).z();
      o.radius_px = on.ball_radius_m * std::sqrt(cams[c].fx * cams[c].fy) / depth;
      o.sigma_px = 0.3;
      views.push_back({c, o});
    }
    e.clean += (TriangulatePoint(cams, views, on).point_world - p).norm() / trials;
    const double angle = rng->Uniform(0, 2 * M_PI);
    BallObservation& partial = views[trial % 4].observation;
    partial.centre_px +=
        (1 - shrink) * partial.radius_px * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    partial.radius_px *= shrink;
    const TriangulationResult a = TriangulatePoint(cams, views, on);
    const TriangulationResult b = TriangulatePoint(cams, views, off);
    EXPECT_TRUE(a.ok() && b.ok());
    e.weighted += (a.point_world - p).norm() / trials;
    e.unweighted += (b.point_world - p).norm() / trials;
  }
  std::cout << "partial disc (" << shrink << " of the radius): mean error " << e.weighted * 1e3
            << " mm, unweighted " << e.unweighted * 1e3 << " mm, clean " << e.clean * 1e3
            << " mm\n";
  return e;
}

TEST(Triangulation, AViewWhoseRadiusDisagreesWeighsLess) {
  testing::SeededRng rng(17);
  // The lit part only: most of what the partial disc adds is gone.
  const PartialDiscErrors lit = PartialDisc(0.7, &rng);
  EXPECT_LT(lit.weighted - lit.clean, 0.3 * (lit.unweighted - lit.clean));
  EXPECT_LT(lit.clean, 0.008);
  // A shaded rim lost (10 % of the radius, 1-2 px here): more than the radius' own noise. Over
  // seeds 1-30 the weighting leaves 0.31-0.61 of the excess (the lit part's: 0.05-0.16).
  const PartialDiscErrors rim = PartialDisc(0.9, &rng);
  EXPECT_LT(rim.weighted - rim.clean, 0.75 * (rim.unweighted - rim.clean));
}

TEST(Triangulation, OutlineCentreModelRemovesThePerspectiveBias) {
  // Project points of the sphere's silhouette (the tangent circle) with the camera, fit an
  // ellipse: its centre is what a detector measures, and the model must predict it.
  camera::Camera cam = camera::Camera::FromFov(1280, 960, 75);
  cam.cam_from_world = geometry::Rigid3d::LookAt({-11, -8, 6}, {0, 0, 0});
  cam.has_pose = true;
  const double r = 0.11;
  for (const Eigen::Vector3d& ball :
       {Eigen::Vector3d(-8, -3, 0.11), Eigen::Vector3d(4, 5, 2.0), Eigen::Vector3d(-2, 3, 0.5)}) {
    const Eigen::Vector3d c = cam.CentreInWorld();
    const Eigen::Vector3d axis = (ball - c).normalized();
    const double d = (ball - c).norm();
    // Tangent points: circle of radius r*sqrt(d^2-r^2)/d around the point at d - r^2/d.
    const double rho = r * std::sqrt(d * d - r * r) / d;
    const Eigen::Vector3d centre = c + axis * (d - r * r / d);
    const Eigen::Vector3d u = axis.unitOrthogonal(), v = axis.cross(u);
    std::vector<cv::Point2f> outline;
    for (int i = 0; i < 360; ++i) {
      const double a = i * M_PI / 180.0;
      const auto uv = cam.Project(centre + rho * (std::cos(a) * u + std::sin(a) * v));
      ASSERT_TRUE(uv.has_value());
      outline.emplace_back(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
    }
    const cv::RotatedRect ellipse = cv::fitEllipse(outline);
    const Eigen::Vector2d measured(ellipse.center.x, ellipse.center.y);
    const Eigen::Vector2d model = *PredictBallCentre(cam, ball, r);
    const Eigen::Vector2d point = *PredictBallCentre(cam, ball, 0.0);
    // The naive projection of the centre is off by ten times more or more.
    EXPECT_LT((model - measured).norm(), 1e-3);
    EXPECT_GT((point - measured).norm(), 10 * (model - measured).norm());
  }
}

TEST(Triangulation, NearParallelRaysAreDegenerateOrUncertain) {
  // Two cameras side by side looking at a point far away: the ray angle shrinks with distance.
  std::vector<camera::Camera> cams(2, camera::Camera::FromFov(1280, 960, 60));
  cams[0].cam_from_world = geometry::Rigid3d::LookAt({0, -0.5, 1}, {100, 0, 1});
  cams[1].cam_from_world = geometry::Rigid3d::LookAt({0, 0.5, 1}, {100, 0, 1});
  cams[0].has_pose = cams[1].has_pose = true;
  TriangulationOptions opt;
  double last_var = 0;
  for (double x : {10.0, 20.0, 25.0}) {  // ray angles 5.7, 2.9, 2.3 degrees
    const Eigen::Vector3d p(x, 0, 1);
    std::vector<View> views = {{0, Observe(cams[0], p, 0, 0, nullptr)},
                               {1, Observe(cams[1], p, 0, 0, nullptr)}};
    const auto r = TriangulatePoint(cams, views, opt);
    ASSERT_TRUE(r.ok()) << x;
    EXPECT_LT((r.point_world - p).norm(), 1e-6 * x);
    EXPECT_GT(r.covariance(0, 0), last_var);  // depth uncertainty grows
    last_var = r.covariance(0, 0);
  }
  const Eigen::Vector3d far(60, 0, 1);  // 0.95 degrees
  std::vector<View> views = {{0, Observe(cams[0], far, 0, 0, nullptr)},
                             {1, Observe(cams[1], far, 0, 0, nullptr)}};
  EXPECT_EQ(TriangulatePoint(cams, views, opt).status, TriangulationStatus::kDegenerate);
  // The same pixel in two cameras with the same orientation: exactly parallel rays.
  views[1].observation = views[0].observation;
  EXPECT_EQ(TriangulatePoint(cams, views, opt).status, TriangulationStatus::kDegenerate);
  std::vector<std::vector<BallObservation>> cand = {{views[0].observation}, {views[1].observation}};
  EXPECT_EQ(TriangulateRobust(cams, cand, opt).status, TriangulationStatus::kNoConsistentSet);
}

TEST(Triangulation, PointBehindACameraIsRejected) {
  // Camera 1 looks away from the field: the pixel it reports for the ball direction is behind.
  auto cams = CornerCameras();
  const Eigen::Vector3d p(1, 1, 0.5);
  camera::Camera away = cams[1];
  const Eigen::Vector3d eye = cams[1].CentreInWorld();
  away.cam_from_world = geometry::Rigid3d::LookAt(eye, eye + (eye - p));  // p is straight behind it
  // A blob at the image centre of `away` is on the ray pointing away from p.
  std::vector<camera::Camera> two = {cams[0], away};
  BallObservation centre;
  centre.centre_px = {away.cx, away.cy};
  std::vector<View> views = {{0, Observe(cams[0], p, 0, 0, nullptr)}, {1, centre}};
  const auto r = TriangulatePoint(two, views, {});
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.status == TriangulationStatus::kBehindCamera ||
              r.status == TriangulationStatus::kDegenerate)
      << ToString(r.status);
  // In robust mode with the other three cameras the backward camera's blob is simply unused.
  std::vector<camera::Camera> four = {cams[0], away, cams[2], cams[3]};
  std::vector<std::vector<BallObservation>> cand(4);
  for (int c : {0, 2, 3}) cand[c] = {Observe(four[c], p, 0, 0, nullptr)};
  cand[1] = {centre};
  const auto rr = TriangulateRobust(four, cand, {});
  ASSERT_TRUE(rr.ok());
  EXPECT_EQ(rr.num_views(), 3);
  for (const auto& v : rr.views) EXPECT_NE(v.camera, 1);
  EXPECT_LT((rr.point_world - p).norm(), 1e-6);
}

TEST(Triangulation, OneCameraOnlyNeedsTheGroundAssumption) {
  testing::SeededRng rng(14);
  const auto cams = CornerCameras(&rng);
  TriangulationOptions opt;
  opt.ball_radius_m = 0.11;
  const Eigen::Vector3d p(rng.Uniform(-6, 6), rng.Uniform(-4, 4), opt.ball_radius_m);
  const BallObservation obs = Observe(cams[2], p, 0.0, 0, nullptr);
  EXPECT_EQ(TriangulatePoint(cams, {{2, obs}}, opt).status, TriangulationStatus::kTooFewViews);
  std::vector<std::vector<BallObservation>> cand(4);
  cand[2] = {obs};
  EXPECT_EQ(TriangulateRobust(cams, cand, opt).status, TriangulationStatus::kTooFewViews);
  opt.single_camera_ground = true;
  const auto r = TriangulateRobust(cams, cand, opt);
  ASSERT_TRUE(r.ok()) << ToString(r.status);
  EXPECT_TRUE(r.on_ground);
  ASSERT_EQ(r.num_views(), 1);
  EXPECT_EQ(r.views[0].camera, 2);
  EXPECT_LT((r.point_world - p).norm(), 1e-6);
  EXPECT_DOUBLE_EQ(r.point_world.z(), opt.ball_radius_m);
  EXPECT_GT(r.covariance(0, 0), 0);
  EXPECT_EQ(r.covariance(2, 2), 0);
  // A pixel above the horizon (the top row: the camera looks 24 deg down, half its field of view
  // is 30 deg) never reaches the ground. One far outside the image may not undistort at all.
  BallObservation sky;
  sky.centre_px = {640, 0};
  EXPECT_EQ(LocateOnGround(cams[2], 2, sky, opt).status, TriangulationStatus::kBehindCamera);
}

TEST(Triangulation, FalseBlobInOneCameraNeverMovesTheBall) {
  testing::SeededRng rng(15);
  const auto cams = CornerCameras(&rng);
  TriangulationOptions opt;
  opt.outline_centre = true;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::Vector3d p = RandomBall(rng);
    std::vector<std::vector<BallObservation>> cand(4);
    std::vector<View> truth_views;
    for (int c = 0; c < 4; ++c) {
      cand[c] = {Observe(cams[c], p, opt.ball_radius_m, 0.5, &rng)};
      truth_views.push_back({c, cand[c][0]});
    }
    const auto reference = TriangulatePoint(cams, truth_views, opt);
    ASSERT_TRUE(reference.ok());
    // A false blob, with a better score, in a random camera anywhere in its image but on the ball
    // (at seed 32 one fell 3.2 px from it, within the inlier threshold: no false blob then).
    const int bad = rng.UniformInt(0, 3);
    BallObservation fake;
    do {
      fake.centre_px = {rng.Uniform(0, 1279), rng.Uniform(0, 959)};
    } while ((fake.centre_px - cand[bad][0].centre_px).norm() < 5 * opt.inlier_threshold_px);
    fake.score = 5.0;
    cand[bad].insert(cand[bad].begin() + rng.UniformInt(0, 1), fake);
    const auto r = TriangulateRobust(cams, cand, opt);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.num_views(), 4);
    EXPECT_LT((r.point_world - reference.point_world).norm(), 1e-9);
    // The false blob as the only blob of that camera: the other three place the ball.
    cand[bad] = {fake};
    truth_views.erase(truth_views.begin() + bad);
    const auto three = TriangulatePoint(cams, truth_views, opt);
    const auto r3 = TriangulateRobust(cams, cand, opt);
    ASSERT_TRUE(r3.ok());
    EXPECT_EQ(r3.num_views(), 3);
    EXPECT_LT((r3.point_world - three.point_world).norm(), 1e-9);
  }
}

TEST(Triangulation, BadInputThrowsNamingIt) {
  const auto cams = CornerCameras();
  BallObservation nan_obs;
  nan_obs.centre_px = {NAN, 3};
  EXPECT_THROW(TriangulatePoint(cams, {{0, nan_obs}, {1, nan_obs}}), Error);
  EXPECT_THROW(TriangulatePoint(cams, {{0, {}}, {7, {}}}), Error);
  EXPECT_THROW(TriangulateRobust(cams, {{}, {}}), Error);
  auto no_pose = cams;
  no_pose[1].has_pose = false;
  EXPECT_THROW(TriangulatePoint(no_pose, {{0, {}}, {1, {}}}), Error);
  TriangulationOptions opt;
  opt.inlier_threshold_px = -1;
  EXPECT_THAT([&] { opt.Check(); }, ThrowsMessage<Error>(HasSubstr("inlier_threshold_px")));
  opt = {};
  opt.max_radius_ratio = 0.5;
  EXPECT_THROW(opt.Check(), Error);
}

// Weak candidates (a ball that failed a single-view shape check) complete a position that an
// accepted candidate starts, never move one that accepted candidates give, and alone count only
// when three or more cameras agree near the predicted position (a cone is consistent too).
TEST(Triangulation, WeakCandidatesOnlyCompleteOrConfirm) {
  testing::SeededRng rng(21);
  const auto cams = CornerCameras(&rng);
  TriangulationOptions opt;
  opt.ball_radius_m = 0.11;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d ball = RandomBall(rng), cone(rng.Uniform(-8, 8), rng.Uniform(-5, 5), 0.2);
    if ((ball - cone).norm() < 2.0) continue;
    auto weak = [&](int c, const Eigen::Vector3d& p) {
      BallObservation o = Observe(cams[c], p, 0.0, 0.3, &rng);
      o.weak = true;
      o.score = 0.9;  // higher than the accepted ones: the score must not decide
      return o;
    };
    auto strong = [&](int c) {
      BallObservation o = Observe(cams[c], ball, 0.0, 0.3, &rng);
      o.score = 0.5;
      return o;
    };
    // Accepted candidates in two cameras, a consistent cone seen weakly by all four: the ball.
    std::vector<std::vector<BallObservation>> cand(4);
    for (int c = 0; c < 4; ++c) cand[c].push_back(weak(c, cone));
    cand[0].push_back(strong(0));
    cand[2].push_back(strong(2));
    auto r = TriangulateRobust(cams, cand, opt);
    ASSERT_TRUE(r.ok()) << ToString(r.status);
    EXPECT_EQ(r.weak_views, 0);
    EXPECT_LT((r.point_world - ball).norm(), 0.05);
    // One accepted view of the ball plus a weak one in another camera: completed.
    cand.assign(4, {});
    cand[1] = {strong(1)};
    cand[3] = {weak(3, ball), weak(3, cone)};
    r = TriangulateRobust(cams, cand, opt);
    ASSERT_TRUE(r.ok()) << ToString(r.status);
    EXPECT_EQ(r.weak_views, 1);
    EXPECT_EQ(r.num_views(), 2);
    EXPECT_LT((r.point_world - ball).norm(), 0.05);
    opt.use_weak = false;
    EXPECT_FALSE(TriangulateRobust(cams, cand, opt).ok());
    opt.use_weak = true;
    // Weak views only: two are never enough; four need a prior near them.
    cand.assign(4, {});
    cand[0] = {weak(0, ball)};
    cand[1] = {weak(1, ball)};
    EXPECT_FALSE(TriangulateRobust(cams, cand, opt, &ball).ok());
    for (int c = 0; c < 4; ++c) cand[c] = {weak(c, ball), weak(c, cone)};
    EXPECT_FALSE(TriangulateRobust(cams, cand, opt).ok());  // no prior
    const Eigen::Vector3d near_ball = ball + Eigen::Vector3d(0.3, -0.2, 0.1);
    r = TriangulateRobust(cams, cand, opt, &near_ball);
    ASSERT_TRUE(r.ok()) << ToString(r.status);
    EXPECT_EQ(r.weak_views, 4);
    EXPECT_LT((r.point_world - ball).norm(), 0.05);
    const Eigen::Vector3d near_cone = cone + Eigen::Vector3d(0.2, 0.2, 0.0);
    r = TriangulateRobust(cams, cand, opt, &near_cone);
    ASSERT_TRUE(r.ok());
    EXPECT_LT((r.point_world - cone).norm(), 0.05);  // what the prior asks for
    const Eigen::Vector3d far(50, 50, 1);
    EXPECT_FALSE(TriangulateRobust(cams, cand, opt, &far).ok());
  }
}

// A static ball-like object that three cameras agree on takes the place of a ball two cameras
// see, unless a prior (the tracked ball's predicted position) says where the ball can be: then
// only hypotheses near it count, and with a prior far from both there is no position.
TEST(Triangulation, APriorGatesTheHypotheses) {
  testing::SeededRng rng(23);
  const auto cams = CornerCameras(&rng);
  TriangulationOptions opt;
  opt.ball_radius_m = 0.11;
  int trials = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d ball = RandomBall(rng);
    const Eigen::Vector3d thing(rng.Uniform(-8, 8), rng.Uniform(-5, 5), rng.Uniform(0.3, 2.0));
    if ((ball - thing).norm() < 3.0) continue;
    ++trials;
    auto seen = [&](int c, const Eigen::Vector3d& p) {
      BallObservation o = Observe(cams[c], p, 0.0, 0.3, &rng);
      o.score = 0.6;
      return o;
    };
    std::vector<std::vector<BallObservation>> cand(4);
    for (int c = 0; c < 3; ++c) cand[c].push_back(seen(c, thing));
    cand[2].push_back(seen(2, ball));
    cand[3].push_back(seen(3, ball));
    auto r = TriangulateRobust(cams, cand, opt);
    ASSERT_TRUE(r.ok()) << ToString(r.status);
    EXPECT_LT((r.point_world - thing).norm(), 0.05);  // more cameras win without a prior
    const Eigen::Vector3d expected = ball + Eigen::Vector3d(0.4, -0.3, 0.1);
    r = TriangulateRobust(cams, cand, opt, &expected);
    ASSERT_TRUE(r.ok()) << ToString(r.status);
    EXPECT_LT((r.point_world - ball).norm(), 0.05);
    EXPECT_EQ(r.num_views(), 2);
    // Nothing near a far prior: the set of 3 cameras elsewhere is taken (the ball moved there),
    // a set of fewer than prior_override_views never.
    const Eigen::Vector3d far(50, 50, 1);
    r = TriangulateRobust(cams, cand, opt, &far);
    ASSERT_TRUE(r.ok()) << ToString(r.status);
    EXPECT_LT((r.point_world - thing).norm(), 0.05);
    opt.prior_override_views = 4;
    EXPECT_FALSE(TriangulateRobust(cams, cand, opt, &far).ok());
    opt.prior_override_views = 0;
    EXPECT_FALSE(TriangulateRobust(cams, cand, opt, &far).ok());
    opt.prior_override_views = 3;
    opt.gate_by_prior = false;  // the prior then only admits weak sets
    r = TriangulateRobust(cams, cand, opt, &expected);
    ASSERT_TRUE(r.ok()) << ToString(r.status);
    EXPECT_LT((r.point_world - thing).norm(), 0.05);
    opt.gate_by_prior = true;
  }
  EXPECT_GT(trials, 5);
}

}  // namespace
}  // namespace fv::recon
