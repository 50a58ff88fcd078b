#include "fieldvision/recon/trajectory_physics.h"

#include <gtest/gtest.h>

namespace fv::recon {
namespace {

TEST(FlightPositionAt, ParabolaAndIntegratedFlightAgreeWithoutDragOrSpin) {
  const double p0[3] = {1.0, -2.0, 0.5}, v0[3] = {8.0, 3.0, 6.0}, s0[3] = {0, 0, 0};
  const double g = 9.81;
  for (double dt : {-0.4, 0.0, 0.05, 0.7}) {
    double parabola[3], integrated[3];
    FlightPositionAt(p0, v0, 0.0, s0, g, dt, false, parabola);
    FlightPositionAt(p0, v0, 0.0, s0, g, dt, true, integrated);
    EXPECT_DOUBLE_EQ(parabola[0], p0[0] + v0[0] * dt);
    EXPECT_DOUBLE_EQ(parabola[1], p0[1] + v0[1] * dt);
    EXPECT_DOUBLE_EQ(parabola[2], p0[2] + v0[2] * dt - 0.5 * g * dt * dt);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(integrated[i], parabola[i], 1e-9) << dt;
  }
  // Drag slows the flight: the integrated position falls short of the parabola's along x.
  double parabola[3], dragged[3];
  FlightPositionAt(p0, v0, 0.02, s0, g, 0.7, false, parabola);
  FlightPositionAt(p0, v0, 0.02, s0, g, 0.7, true, dragged);
  EXPECT_LT(dragged[0], parabola[0] - 0.05);
}

}  // namespace
}  // namespace fv::recon
