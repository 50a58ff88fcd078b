#include "fieldvision/plan/optimize.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::plan {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// The seed's reference rig: 4 cameras 1 m outside the corners of the 18 x 12 m field, 4 m high,
// aimed at the centre, 1280 x 960 with 80 degrees horizontal field of view.
std::vector<camera::Camera> CornerRig() {
  std::vector<camera::Camera> cams;
  for (const auto& [x, y] : {std::pair{-10.0, -7.0}, {10.0, -7.0}, {10.0, 7.0}, {-10.0, 7.0}}) {
    cams.push_back(MakeAimedCamera("corner", 1280, 960, 80, {x, y, 4}, {0, 0, 0}));
  }
  return cams;
}

TEST(OptimizeTest, PerimeterMountsEncloseTheField) {
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const auto mounts = PerimeterMounts(field, 1.0, 4.0);
  ASSERT_EQ(mounts.size(), 4u);
  double total = 0;
  for (const auto& m : mounts) {
    total += m.LengthM();
    EXPECT_DOUBLE_EQ(m.a.z(), 4.0);
    EXPECT_DOUBLE_EQ(std::max(std::abs(m.a.x()) - 10.0, std::abs(m.a.y()) - 7.0), 0.0);
  }
  EXPECT_DOUBLE_EQ(total, 2 * (20.0 + 14.0));
}

TEST(OptimizeTest, FindsARigAtLeastAsGoodAsTheCornerRig) {
  const uint64_t seed = fv::testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  CoverageOptions coverage;
  OptimizeOptions o;
  o.seed = seed;
  o.grid_step_m = 1.0;  // coarse so the test stays fast
  o.iterations = 600;
  o.restarts = 1;
  const camera::Camera model = camera::Camera::FromFov(1280, 960, 80);
  const OptimizeResult r = OptimizeRig(field, PerimeterMounts(field, 1.0, 4.0), model, coverage, o);
  const double corner = RigScore(CornerRig(), field, coverage, o.grid_step_m);
  EXPECT_GE(r.score, corner) << r.Summary();
  EXPECT_GE(r.score, r.start_score);
  // The reported score is the rig's score, and the cameras stay on the perimeter at 4 m.
  EXPECT_NEAR(RigScore(r.rig.cameras, field, coverage, o.grid_step_m), r.score, 1e-12);
  // It is the mean of the ball's layers on the ground and in the air: a rig is never searched
  // for the ground alone (one that saw the air worse was reported as better).
  CoverageOptions search_grid = coverage;
  search_grid.grid_step_m = o.grid_step_m;
  const CoverageResult layers = EvaluateCoverage(r.rig.cameras, field, search_grid);
  ASSERT_EQ(layers.layers.size(), 2u);
  EXPECT_NEAR(r.score, 0.5 * (layers.layers[0].score + layers.layers[1].score), 1e-12);
  ASSERT_EQ(r.rig.cameras.size(), 4u);
  for (const camera::Camera& c : r.rig.cameras) {
    const Eigen::Vector3d p = c.CentreInWorld();
    EXPECT_NEAR(p.z(), 4.0, 1e-9);
    EXPECT_NEAR(std::max(std::abs(p.x()) - 10.0, std::abs(p.y()) - 7.0), 0.0, 1e-9);
  }
  // Same seed, same rig.
  const OptimizeResult again =
      OptimizeRig(field, PerimeterMounts(field, 1.0, 4.0), model, coverage, o);
  EXPECT_DOUBLE_EQ(again.score, r.score);
}

TEST(OptimizeTest, PointMountsAndBadOptions) {
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  const nlohmann::json j = {
      {"mounts", {{{"name", "pole"}, {"point", {-10, 0, 6}}}, {{"point", {10, 0, 6}}}}}};
  const auto mounts = MountsFromJson(j, "m.json");
  ASSERT_EQ(mounts.size(), 2u);
  EXPECT_EQ(mounts[0].name, "pole");
  OptimizeOptions o;
  o.num_cameras = 2;
  o.grid_step_m = 1.5;
  o.iterations = 50;
  o.restarts = 1;
  const OptimizeResult r =
      OptimizeRig(field, mounts, camera::Camera::FromFov(1280, 960, 90), CoverageOptions(), o);
  // Cameras can only stand on the two poles.
  for (const camera::Camera& c : r.rig.cameras) {
    EXPECT_NEAR(std::abs(c.CentreInWorld().x()), 10.0, 1e-9);
    EXPECT_NEAR(c.CentreInWorld().z(), 6.0, 1e-9);
  }
  EXPECT_THROW(MountsFromJson({{"mounts", {{{"line", {{0, 0, 1}}}}}}}, "m.json"), Error);
  EXPECT_THAT(
      [&] {
        MountsFromJson({{"mounts", {{{"point", {0, "x", 1}}}}}}, "m.json");
      },
      ThrowsMessage<Error>(HasSubstr("mounts[0].point")));
  o.num_cameras = 0;
  EXPECT_THAT([&] { o.Check(); }, ThrowsMessage<Error>(HasSubstr("num_cameras")));
  // Budgets no rig can meet are errors, not a rig of score 0 (exit 0 and a rig.json before): a
  // mount under the ground, one camera, a lens of 1 degree.
  EXPECT_THAT(
      [&] {
        MountsFromJson({{"mounts", {{{"point", {0, 0, -4}}}}}}, "m.json");
      },
      ThrowsMessage<Error>(HasSubstr("mounts[0]: 4 m below the ground")));
  o.num_cameras = 1;
  EXPECT_THAT([&] { o.Check(); }, ThrowsMessage<Error>(HasSubstr("two cameras or more")));
  o.num_cameras = 2;
  EXPECT_THAT(
      [&] {
        OptimizeRig(field, mounts, camera::Camera::FromFov(1280, 960, 1), CoverageOptions(), o);
      },
      ThrowsMessage<Error>(HasSubstr("no placement of 2 cameras")));
}

}  // namespace
}  // namespace fv::plan
