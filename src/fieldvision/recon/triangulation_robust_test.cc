// The robust search's stages one by one (triangulation_internal.h).
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "fieldvision/camera/sphere_image.h"
#include "fieldvision/recon/triangulation.h"
#include "fieldvision/recon/triangulation_internal.h"
#include "fieldvision/util/error.h"

namespace fv::recon {
namespace {

using namespace detail;  // NOLINT: the stages under test

// Three cameras 10 m from the field centre, 5 m high, looking at it.
std::vector<camera::Camera> RingCameras() {
  std::vector<camera::Camera> cams;
  for (int i = 0; i < 3; ++i) {
    const double a = 2 * M_PI * i / 3;
    camera::Camera c = camera::Camera::FromFov(1280, 960, 70);
    c.cam_from_world = geometry::Rigid3d::LookAt(
        Eigen::Vector3d(10 * std::cos(a), 10 * std::sin(a), 5), {0, 0, 0});
    c.has_pose = true;
    cams.push_back(c);
  }
  return cams;
}

BallObservation Seen(const camera::Camera& cam, const Eigen::Vector3d& p, double score = 1.0) {
  BallObservation o;
  o.centre_px = *PredictBallCentre(cam, p, 0.0);
  o.score = score;
  return o;
}

// Seen with a centre known to 0.2 px.
BallObservation SeenSharp(const camera::Camera& cam, const Eigen::Vector3d& p, double score) {
  BallObservation o = Seen(cam, p, score);
  o.sigma_px = 0.2;
  return o;
}

BallObservation Elsewhere(double score) {
  BallObservation o;
  o.centre_px = {100, 120};
  o.score = score;
  return o;
}

TEST(RobustStages, RankKeepsTheBestScoredCandidatesOfCamerasThatSeeAny) {
  const auto cams = RingCameras();
  TriangulationOptions o;
  o.max_candidates_per_camera = 2;
  std::vector<std::vector<BallObservation>> cand = {
      {Elsewhere(0.1), Elsewhere(0.9), Elsewhere(0.5)}, {}, {Elsewhere(0.3)}};
  const RankedCandidates r = RankCandidates(cams, cand, o);
  EXPECT_EQ(r.seen, (std::vector<int>{0, 2}));
  EXPECT_EQ(r.order[0], (std::vector<int>{1, 2}));  // 0.9, 0.5; the 0.1 one dropped
  EXPECT_TRUE(r.order[1].empty());
  EXPECT_TRUE(r.rays[0][1].has_value());
  EXPECT_FALSE(r.rays[0][0].has_value());  // not ranked: no ray cast
}

TEST(RobustStages, ConsistencyChecksThresholdDepthAndRadius) {
  const auto cams = RingCameras();
  TriangulationOptions o;
  const Eigen::Vector3d p(1, -2, 0.5);
  BallObservation obs = Seen(cams[0], p);
  EXPECT_NEAR(ConsistentError(cams[0], obs, p, o), 0.0, 1e-9);
  obs.centre_px.x() += 3.0;  // within max(4 px, 3 sigma)
  EXPECT_NEAR(ConsistentError(cams[0], obs, p, o), 3.0, 1e-9);
  obs.centre_px.x() += 2.0;  // 5 px: outside
  EXPECT_EQ(ConsistentError(cams[0], obs, p, o), -1);
  // Behind the camera.
  EXPECT_EQ(ConsistentError(cams[0], Seen(cams[0], p), Eigen::Vector3d(30, 0, 8), o), -1);
  // Radius: the depth predicts r = 0.11 * f / depth; twice that fails a 1.5 ratio.
  BallObservation sized = Seen(cams[0], p);
  const double depth = (cams[0].cam_from_world * p).z();
  sized.radius_px = 2 * 0.11 * std::sqrt(cams[0].fx * cams[0].fy) / depth;
  EXPECT_TRUE(RadiusConsistent(cams[0], sized, p, 0.11, 0.0));  // off
  EXPECT_TRUE(RadiusConsistent(cams[0], sized, p, 0.11, 2.5));
  EXPECT_FALSE(RadiusConsistent(cams[0], sized, p, 0.11, 1.5));
  sized.weak = true;  // weak candidates also meet weak_max_radius_ratio (1.5)
  EXPECT_EQ(ConsistentError(cams[0], sized, p, o), -1);
  // Larger than expected by a third: within 1.5 either way, beyond max_larger_radius_ratio (1.25);
  // smaller by as much passes.
  BallObservation larger = Seen(cams[0], p);
  larger.radius_px = sized.radius_px / 2 * 4.0 / 3.0;
  EXPECT_TRUE(RadiusConsistent(cams[0], larger, p, 0.11, 1.5));
  EXPECT_FALSE(RadiusConsistent(cams[0], larger, p, 0.11, 1.5, 1.25));
  EXPECT_FALSE(RadiusConsistent(cams[0], larger, p, 0.11, 0.0, 1.25));
  EXPECT_EQ(ConsistentError(cams[0], larger, p, o), -1);
  BallObservation smaller = larger;
  smaller.radius_px = sized.radius_px / 2 * 3.0 / 4.0;
  EXPECT_TRUE(RadiusConsistent(cams[0], smaller, p, 0.11, 1.5, 1.25));
  EXPECT_GE(ConsistentError(cams[0], smaller, p, o), 0.0);
  o.max_larger_radius_ratio = 0.0;
  EXPECT_GE(ConsistentError(cams[0], larger, p, o), 0.0);
  o.max_larger_radius_ratio = 1.0;
  EXPECT_THROW(o.Check(), Error);
}

// Two cameras' still objects of the ball's colour that meet at a point by chance, scored above
// the ball that the two other cameras see: their sizes do not fit that point, so the ball is
// taken (max_radius_ratio); with any radius allowed, the better scored ghost.
TEST(RobustStages, AGhostWhoseSizesDoNotFitItIsNoBall) {
  std::vector<camera::Camera> cams = RingCameras();
  camera::Camera fourth = cams[0];
  fourth.cam_from_world = geometry::Rigid3d::LookAt(Eigen::Vector3d(0, 0, 12), {0.1, 0.2, 0});
  cams.push_back(fourth);
  const Eigen::Vector3d ball(1.0, -1.0, 0.6), ghost(-2.0, 2.5, 1.5);
  const auto sized = [](const camera::Camera& cam, const Eigen::Vector3d& p, double size,
                        double score) {
    BallObservation o = Seen(cam, p, score);
    o.radius_px = size * 0.11 * std::sqrt(cam.fx * cam.fy) / (cam.cam_from_world * p).z();
    return o;
  };
  const std::vector<std::vector<BallObservation>> cand = {{sized(cams[0], ball, 1.0, 0.5)},
                                                          {sized(cams[1], ball, 1.0, 0.5)},
                                                          {sized(cams[2], ghost, 2.2, 0.9)},
                                                          {sized(cams[3], ghost, 0.4, 0.9)}};
  TriangulationOptions o;
  const TriangulationResult r = TriangulateRobust(cams, cand, o);
  ASSERT_TRUE(r.ok());
  EXPECT_LT((r.point_world - ball).norm(), 1e-3);
  // Any radius allowed: the scores weighted by the sizes' fit still take the ball; the scores
  // alone, the better scored ghost.
  o.max_radius_ratio = 0.0;
  o.max_larger_radius_ratio = 0.0;
  const TriangulationResult weighted = TriangulateRobust(cams, cand, o);
  ASSERT_TRUE(weighted.ok());
  EXPECT_LT((weighted.point_world - ball).norm(), 1e-3);
  o.score_radius_sigma = 0.0;
  const TriangulationResult any = TriangulateRobust(cams, cand, o);
  ASSERT_TRUE(any.ok());
  EXPECT_LT((any.point_world - ghost).norm(), 1e-3);
}

// The ball accepted by one camera only, and two faint still things in two others that meet at a
// point: no position there (min_two_view_score), unless the ball is expected there (a prior) or
// the two are scored as balls are.
TEST(RobustStages, TwoFaintViewsFarFromThePriorAreNoBall) {
  const auto cams = RingCameras();
  const Eigen::Vector3d ghost(-2.0, 2.5, 1.5);
  std::vector<std::vector<BallObservation>> cand = {
      {Elsewhere(0.8)}, {Seen(cams[1], ghost, 0.07)}, {Seen(cams[2], ghost, 0.1)}};
  TriangulationOptions o;
  EXPECT_FALSE(TriangulateRobust(cams, cand, o).ok());
  const Eigen::Vector3d near_ghost = ghost + Eigen::Vector3d(0.3, 0, 0);
  const TriangulationResult expected = TriangulateRobust(cams, cand, o, &near_ghost);
  ASSERT_TRUE(expected.ok());
  EXPECT_LT((expected.point_world - ghost).norm(), 1e-3);
  o.min_two_view_score = 0.0;
  EXPECT_TRUE(TriangulateRobust(cams, cand, o).ok());
  o = TriangulationOptions();
  cand[1][0].score = cand[2][0].score = 0.15;  // 0.3 together
  EXPECT_TRUE(TriangulateRobust(cams, cand, o).ok());
  o.min_two_view_score = -1;
  EXPECT_THROW(o.Check(), Error);
}

// Two cameras alone: a thing that came into view in one (its disc differs from the camera's
// background) and one that was always there in the other are no ball, wherever their rays meet
// (still_max_change); both new, both still, or either not compared with a background: a ball.
TEST(RobustStages, ANewThingAndAStillThingAreNoBall) {
  const auto cams = RingCameras();
  const Eigen::Vector3d p(-2.0, 2.5, 1.5);
  const auto pair = [&](double change_a, double change_b) {
    std::vector<std::vector<BallObservation>> cand = {
        {Seen(cams[0], p, 0.5)}, {Seen(cams[1], p, 0.5)}, {}};
    cand[0][0].background_change = change_a;
    cand[1][0].background_change = change_b;
    return cand;
  };
  TriangulationOptions o;
  EXPECT_FALSE(TriangulateRobust(cams, pair(0.95, 0.02), o).ok());
  EXPECT_FALSE(TriangulateRobust(cams, pair(0.0, 0.8), o).ok());
  for (const auto& [a, b] :
       {std::pair{0.95, 0.9}, {0.02, 0.0}, {-1.0, 0.0}, {0.95, -1.0}, {0.5, 0.0}, {0.95, 0.3}}) {
    const TriangulationResult r = TriangulateRobust(cams, pair(a, b), o);
    ASSERT_TRUE(r.ok()) << a << " " << b;
    EXPECT_LT((r.point_world - p).norm(), 1e-3);
  }
  // A third camera that agrees outvotes the disagreement.
  std::vector<std::vector<BallObservation>> three = pair(0.95, 0.02);
  three[2] = {Seen(cams[2], p, 0.5)};
  EXPECT_TRUE(TriangulateRobust(cams, three, o).ok());
  o.still_max_change = 0.0;
  EXPECT_TRUE(TriangulateRobust(cams, pair(0.95, 0.02), o).ok());
  o.still_max_change = 0.8;
  EXPECT_THROW(o.Check(), Error);
}

// One camera's ball paired with another camera's still ball-coloured thing on that camera's ray,
// 30 % farther: as many cameras as the ball's own pair and a higher total score, but the first
// camera's radius does not fit the farther point (score_radius_sigma), so the ball is taken;
// with the scores alone, the pair along the ray.
TEST(RobustStages, APairAlongOneCamerasRayGivesWayWhereItsRadiusDoesNotFit) {
  const std::vector<camera::Camera> cams = RingCameras();
  const Eigen::Vector3d ball(1.0, -1.0, 1.5);
  const Eigen::Vector3d eye = cams[0].cam_from_world.Inverse().translation;
  const Eigen::Vector3d thing = eye + 1.3 * (ball - eye);
  const auto sized = [](const camera::Camera& cam, const Eigen::Vector3d& p, double score) {
    BallObservation o = Seen(cam, p, score);
    o.radius_px = *camera::SphereRadiusPx(cam, p, 0.11);
    return o;
  };
  const std::vector<std::vector<BallObservation>> cand = {
      {sized(cams[0], ball, 0.3)}, {sized(cams[1], ball, 0.3)}, {sized(cams[2], thing, 0.45)}};
  TriangulationOptions o;
  ASSERT_GT(o.score_radius_sigma, 0.0);
  const TriangulationResult r = TriangulateRobust(cams, cand, o);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.num_views(), 2);
  EXPECT_LT((r.point_world - ball).norm(), 1e-3);
  EXPECT_NEAR(RadiusWeightedScore(cams[0], cand[0][0], ball, o), 0.3, 1e-9);
  EXPECT_LT(RadiusWeightedScore(cams[0], cand[0][0], thing, o),
            0.5 * RadiusWeightedScore(cams[0], cand[0][0], ball, o));
  // The scores alone: cam0's radius 1.3 times larger than the thing's depth predicts still rules
  // the pair along the ray out (max_larger_radius_ratio); without that rule too, the thing.
  o.score_radius_sigma = 0.0;
  const TriangulationResult larger_rule = TriangulateRobust(cams, cand, o);
  ASSERT_TRUE(larger_rule.ok());
  EXPECT_LT((larger_rule.point_world - ball).norm(), 1e-3);
  o.max_larger_radius_ratio = 0.0;
  const TriangulationResult scores_only = TriangulateRobust(cams, cand, o);
  ASSERT_TRUE(scores_only.ok());
  EXPECT_LT((scores_only.point_world - thing).norm(), 1e-3);
}

TEST(RobustStages, SearchFindsTheLargestAgreeingSetAndRefineKeepsIt) {
  const auto cams = RingCameras();
  TriangulationOptions o;
  const Eigen::Vector3d p(0.5, 1.5, 1.2);
  // Camera 1's best-scored blob is false.
  std::vector<std::vector<BallObservation>> cand = {
      {Seen(cams[0], p)}, {Elsewhere(5.0), Seen(cams[1], p)}, {Seen(cams[2], p)}};
  const RankedCandidates ranked = RankCandidates(cams, cand, o);
  std::vector<int> pick;
  EXPECT_NEAR(GatherConsistent(cams, cand, ranked, o, p, &pick), 0.0, 1e-12);
  EXPECT_EQ(pick, (std::vector<int>{0, 1, 0}));
  EXPECT_EQ(CountPicked(pick), 3);
  const BestHypothesis best = SearchHypotheses(cams, cand, ranked, o, false, nullptr);
  EXPECT_EQ(best.n, 3);
  EXPECT_EQ(best.pick, (std::vector<int>{0, 1, 0}));
  EXPECT_GE(best.hypotheses, 3);
  const TriangulationResult r = RefineConsistentSet(cams, cand, ranked, o, best.pick);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.num_views(), 3);
  EXPECT_LT((r.point_world - p).norm(), 1e-6);
  // A view 20 px off in a set of three is dropped after refinement.
  std::vector<std::vector<BallObservation>> off = cand;
  off[2][0].centre_px.x() += 20;
  const TriangulationResult r2 = RefineConsistentSet(cams, off, ranked, o, {0, 1, 0});
  ASSERT_TRUE(r2.ok());
  EXPECT_EQ(r2.num_views(), 2);
}

TEST(RobustStages, WeakOnlySetsNeedEnoughCamerasNearThePrior) {
  TriangulationOptions o;  // min_views_all_weak 3, prior_gate_m 1
  BallObservation weak;
  weak.weak = true;
  const std::vector<std::vector<BallObservation>> cand = {{weak}, {weak}, {weak, Elsewhere(1)}};
  const Eigen::Vector3d p(1, 1, 1), near(1.5, 1, 1), far(3, 1, 1);
  EXPECT_TRUE(StrongEnough(cand, {-1, 0, 1}, p, o, nullptr));  // one that is not weak
  EXPECT_FALSE(StrongEnough(cand, {0, 0, -1}, p, o, &near));   // two weak views
  EXPECT_FALSE(StrongEnough(cand, {0, 0, 0}, p, o, nullptr));  // no prior
  EXPECT_FALSE(StrongEnough(cand, {0, 0, 0}, p, o, &far));
  EXPECT_TRUE(StrongEnough(cand, {0, 0, 0}, p, o, &near));
}

TEST(RobustStages, BelowRestAllowsForTheHeightUncertainty) {
  TriangulationOptions o;  // ball_radius_m 0.11, max_below_rest_m 0.015
  EXPECT_FALSE(BelowRest(Eigen::Vector3d(0, 0, 0.11), o));
  EXPECT_FALSE(BelowRest(Eigen::Vector3d(0, 0, 0.096), o));
  EXPECT_TRUE(BelowRest(Eigen::Vector3d(0, 0, 0.08), o));
  EXPECT_FALSE(BelowRest(Eigen::Vector3d(0, 0, 0.08), o, 0.005));  // within 3 sigma
  o.max_below_rest_m = -1;                                         // off
  EXPECT_FALSE(BelowRest(Eigen::Vector3d(0, 0, -1), o));
}

// A low orange object (a marker disc, a cone's base) that every camera sees and scores higher
// than the ball is no ball: the search drops it and finds the ball that fewer cameras see.
TEST(RobustTriangulation, ALowObjectSeenByEveryCameraGivesWayToTheBall) {
  const auto cams = RingCameras();
  TriangulationOptions o;
  const Eigen::Vector3d marker(2.0, -1.0, 0.03), ball(-1.0, 1.5, 0.11);
  std::vector<std::vector<BallObservation>> cand = {
      {SeenSharp(cams[0], marker, 0.9), SeenSharp(cams[0], ball, 0.6)},
      {SeenSharp(cams[1], marker, 0.9), SeenSharp(cams[1], ball, 0.6)},
      {SeenSharp(cams[2], marker, 0.9)}};
  const TriangulationResult r = TriangulateRobust(cams, cand, o);
  ASSERT_TRUE(r.ok()) << ToString(r.status);
  EXPECT_EQ(r.num_views(), 2);
  EXPECT_LT((r.point_world - ball).norm(), 1e-3);
  // With the check off the marker wins (three cameras).
  o.max_below_rest_m = -1;
  const TriangulationResult off = TriangulateRobust(cams, cand, o);
  ASSERT_TRUE(off.ok());
  EXPECT_LT((off.point_world - marker).norm(), 1e-3);
}

// An advertising board behind the goal that every camera sees and scores higher than the ball:
// with the field's box as the allowed region it gives way to the ball.
TEST(RobustTriangulation, AnObjectOutsideTheAllowedRegionGivesWayToTheBall) {
  const auto cams = RingCameras();
  TriangulationOptions o;
  const Eigen::Vector3d board(-6.5, 0.5, 0.4), ball(1.0, 1.5, 0.6);
  std::vector<std::vector<BallObservation>> cand = {
      {SeenSharp(cams[0], board, 0.9), SeenSharp(cams[0], ball, 0.6)},
      {SeenSharp(cams[1], board, 0.9), SeenSharp(cams[1], ball, 0.6)},
      {SeenSharp(cams[2], board, 0.9)}};
  const TriangulationResult anywhere = TriangulateRobust(cams, cand, o);
  ASSERT_TRUE(anywhere.ok());
  EXPECT_LT((anywhere.point_world - board).norm(), 1e-3);
  o.allowed_region = Eigen::AlignedBox3d(Eigen::Vector3d(-5, -4, -1), Eigen::Vector3d(5, 4, 8));
  const TriangulationResult r = TriangulateRobust(cams, cand, o);
  ASSERT_TRUE(r.ok()) << ToString(r.status);
  EXPECT_LT((r.point_world - ball).norm(), 1e-3);
  EXPECT_TRUE(NoBallThere(board, o));
  EXPECT_FALSE(NoBallThere(ball, o));
  o.allowed_region.max().x() = std::nan("");
  EXPECT_THROW(o.Check(), Error);
}

}  // namespace
}  // namespace fv::recon
