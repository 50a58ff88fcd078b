#include "fieldvision/camera/sphere_image.h"

#include <cmath>

#include <gtest/gtest.h>

namespace fv::camera {
namespace {

// On the optical axis of a lens without distortion a ball of radius r at depth z spans f r / z.
TEST(SphereRadiusPx, PinholeOnTheAxis) {
  Camera cam = Camera::FromFov(1000, 800, 90);  // f = 500 px
  cam.has_pose = true;                          // identity: looking along +z
  const auto r = SphereRadiusPx(cam, {0, 0, 10}, 0.11);
  ASSERT_TRUE(r);
  EXPECT_NEAR(*r, 500.0 * 0.11 / 10.0, 1e-9);
  EXPECT_FALSE(SphereRadiusPx(cam, {0, 0, -10}, 0.11));  // behind the camera
}

// A barrel lens shrinks things near the border: there the ball is smaller than without the lens
// by the lens' stretches across the image radius (1 + k1 r^2) and along it (1 + 3 k1 r^2), about
// their mean (the two sample directions are perpendicular, at any angle to the image radius).
TEST(SphereRadiusPx, BarrelLensShrinksTheBallNearTheBorder) {
  Camera pinhole = Camera::FromFov(1000, 800, 90);
  pinhole.has_pose = true;
  Camera barrel = pinhole;
  barrel.distortion = {-0.2, 0, 0, 0, 0};
  EXPECT_NEAR(*SphereRadiusPx(barrel, {0, 0, 10}, 0.11), *SphereRadiusPx(pinhole, {0, 0, 10}, 0.11),
              1e-3);  // the lens at the ball's edge (normalised radius 0.011): 2.4e-5
  const Eigen::Vector3d off_axis(6, 0, 10);  // normalised image radius 0.6
  const auto with_lens = SphereRadiusPx(barrel, off_axis, 0.11);
  const auto without = SphereRadiusPx(pinhole, off_axis, 0.11);
  ASSERT_TRUE(with_lens && without);
  const double r2 = 0.36;
  const double mean_stretch = 0.5 * ((1 - 0.2 * r2) + (1 - 3 * 0.2 * r2));  // 0.856
  EXPECT_NEAR(*with_lens / *without, mean_stretch, 0.03);
}

}  // namespace
}  // namespace fv::camera
