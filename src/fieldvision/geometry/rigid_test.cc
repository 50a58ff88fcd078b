#include "fieldvision/geometry/rigid.h"

#include <gtest/gtest.h>

#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::geometry {
namespace {

TEST(Rigid3d, RvecRoundTripAndInverse) {
  testing::SeededRng rng(7);
  for (int i = 0; i < 100; ++i) {
    Eigen::Vector3d rvec(rng.Normal(), rng.Normal(), rng.Normal());
    if (rvec.norm() > 3.0) rvec *= 3.0 / rvec.norm();
    const Eigen::Vector3d tvec(rng.Normal(), rng.Normal(), rng.Normal());
    const Rigid3d t = Rigid3d::FromRvecTvec(rvec, tvec);
    EXPECT_LT((t.Rvec() - rvec).norm(), 1e-9);
    const Eigen::Vector3d p(rng.Normal(), rng.Normal(), rng.Normal());
    EXPECT_LT((t.Inverse() * (t * p) - p).norm(), 1e-12);
    EXPECT_NEAR(RotationAngleBetween(t.rotation, t.rotation), 0.0, 1e-9);
  }
}

TEST(Rigid3d, LookAtPutsTargetOnOpticalAxis) {
  const Eigen::Vector3d eye(-10, -8, 4), target(0, 0, 0);
  const Rigid3d cam_from_world = Rigid3d::LookAt(eye, target);
  const Eigen::Vector3d t = cam_from_world * target;
  EXPECT_NEAR(t.x(), 0, 1e-12);
  EXPECT_NEAR(t.y(), 0, 1e-12);
  EXPECT_GT(t.z(), 0);
  // A point above the target appears higher in the image (smaller y).
  EXPECT_LT((cam_from_world * Eigen::Vector3d(0, 0, 1)).y(), 0);
  EXPECT_NEAR(cam_from_world.rotation.determinant(), 1.0, 1e-12);
}

TEST(Ray3d, HorizontalPlane) {
  Ray3d ray{{0, 0, 10}, Eigen::Vector3d(1, 0, -1).normalized()};
  auto p = IntersectHorizontalPlane(ray, 0.0);
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->x(), 10, 1e-12);
  EXPECT_FALSE(IntersectHorizontalPlane(ray, 20.0));
  EXPECT_FALSE(IntersectHorizontalPlane({{0, 0, 1}, {1, 0, 0}}, 0.0));
}

}  // namespace
}  // namespace fv::geometry
