// Ball motion of the synthetic world: kicks start ballistic flights under gravity and quadratic
// air drag (F = 0.5 rho Cd A v^2), integrated with classical RK4 at a fixed step; a ground contact
// (bottom at z = 0) is located exactly by bisection, reflects the vertical speed by the
// restitution and removes a share of the horizontal speed; slow bounces turn into rolling with
// rolling resistance. The state is stored at every step and at every contact, and read back at
// any time by cubic Hermite interpolation (error far below a micrometre).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "fieldvision/synth/synth.h"

namespace fv::synth {

class BallTrajectory {
 public:
  // Simulates the kicks of `ball` from the first kick to end_time_s (and on until the last
  // flight that starts before end_time_s has landed). No kicks: the ball never moves.
  BallTrajectory(const BallSpec& ball, double end_time_s);

  Eigen::Vector3d PositionAt(double time_s) const;
  Eigen::Vector3d VelocityAt(double time_s) const;
  // Airborne arcs in time order (only those starting before end_time_s).
  const std::vector<Flight>& flights() const { return flights_; }
  int num_samples() const { return static_cast<int>(t_.size()); }

 private:
  void Push(double t, const Eigen::Vector3d& p, const Eigen::Vector3d& v);
  std::vector<double> t_;
  std::vector<Eigen::Vector3d> p_, v_;
  std::vector<Flight> flights_;
};

}  // namespace fv::synth
