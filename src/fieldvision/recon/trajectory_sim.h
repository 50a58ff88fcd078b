// A bouncing-ball simulator with exact ground truth for the trajectory tests and demos: point
// mass under gravity and quadratic drag (RK4, 0.5 ms steps), bounces with normal restitution and
// tangential friction factors, rolling with constant deceleration, kicks and hits that set the
// velocity at given times. Sampling adds Gaussian noise, dropped frames and outliers.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/util/random.h"

namespace fv::recon {

struct BallKick {
  double time_s = 0.0;
  Eigen::Vector3d v_mps = Eigen::Vector3d::Zero();  // velocity right after the kick
};

struct BallSimOptions {
  Eigen::Vector3d start_m = Eigen::Vector3d(0, 0, 0.11);  // centre at time 0 (at rest)
  std::vector<BallKick> kicks;                            // in time order
  double duration_s = 4.0;
  double gravity_mps2 = 9.81;
  double drag_per_m = 0.0;  // k in a = g - k |v| v
  double ball_radius_m = 0.11;
  double ground_z_m = 0.0;
  double restitution = 0.7;        // vz after / vz before
  double tangential_factor = 0.8;  // horizontal speed after / before a bounce
  double min_bounce_mps = 0.6;     // slower impacts end bouncing: the ball rolls
  double rolling_decel_mps2 = 0.6;
  void Check() const;
};

// Truth of one airborne arc.
struct FlightTruth {
  double t_start_s = 0.0, t_end_s = 0.0;
  Eigen::Vector3d origin_m, landing_m, apex_m, v0_mps;
  bool ends_on_ground = true;  // false: ended by a hit or the end of the simulation
};

class BallSimulation {
 public:
  explicit BallSimulation(const BallSimOptions& options);
  Eigen::Vector3d BallAt(double time_s) const;
  const std::vector<FlightTruth>& Flights() const { return flights_; }
  const BallSimOptions& options() const { return options_; }
  // Samples at fps from t0_s to the end with N(0, noise_m) per axis, each frame dropped with
  // probability dropout and replaced by an outlier (offset of outlier_m in a random direction)
  // with probability outlier_rate.
  std::vector<BallSample> Sample(double fps, double noise_m, double dropout, double outlier_rate,
                                 double outlier_m, util::Rng& rng, double t0_s = 0.0) const;

 private:
  BallSimOptions options_;
  double dt_ = 0.0005;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<FlightTruth> flights_;
};

}  // namespace fv::recon
