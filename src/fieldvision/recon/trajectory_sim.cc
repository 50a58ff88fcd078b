#include "fieldvision/recon/trajectory_sim.h"

#include <algorithm>
#include <cmath>

#include "fieldvision/util/error.h"

namespace fv::recon {

void BallSimOptions::Check() const {
  CheckPositive(duration_s, "duration_s");
  CheckPositive(gravity_mps2, "gravity_mps2");
  CheckNonNegative(drag_per_m, "drag_per_m");
  CheckPositive(ball_radius_m, "ball_radius_m");
  CheckInRange(restitution, 0.0, 1.0, "restitution");
  CheckInRange(tangential_factor, 0.0, 1.0, "tangential_factor");
  CheckNonNegative(min_bounce_mps, "min_bounce_mps");
  CheckNonNegative(rolling_decel_mps2, "rolling_decel_mps2");
  for (size_t i = 1; i < kicks.size(); ++i) {
    FV_REQUIRE(kicks[i].time_s > kicks[i - 1].time_s, "kicks must be in time order (kick {})", i);
  }
}

BallSimulation::BallSimulation(const BallSimOptions& o) : options_(o) {
  o.Check();
  const double zr = o.ground_z_m + o.ball_radius_m;
  const int steps = static_cast<int>(std::ceil(o.duration_s / dt_));
  Eigen::Vector3d p = o.start_m, v = Eigen::Vector3d::Zero();
  bool airborne = p.z() > zr + 1e-9;
  size_t next_kick = 0;
  FlightTruth cur;
  bool in_flight = false;
  auto accel = [&](const Eigen::Vector3d& vel) {
    Eigen::Vector3d a = -o.drag_per_m * vel.norm() * vel;
    a.z() -= o.gravity_mps2;
    return a;
  };
  auto start_flight = [&](double t) {
    cur = FlightTruth();
    cur.t_start_s = t;
    cur.origin_m = p;
    cur.v0_mps = v;
    cur.apex_m = p;
    in_flight = true;
  };
  auto end_flight = [&](double t, bool ground) {
    if (!in_flight) return;
    cur.t_end_s = t;
    cur.landing_m = p;
    cur.ends_on_ground = ground;
    flights_.push_back(cur);
    in_flight = false;
  };
  if (airborne) start_flight(0.0);
  positions_.push_back(p);
  for (int s = 0; s < steps; ++s) {
    const double t = s * dt_;
    if (next_kick < o.kicks.size() && o.kicks[next_kick].time_s <= t + 1e-12) {
      if (in_flight) end_flight(t, false);
      v = o.kicks[next_kick].v_mps;
      ++next_kick;
      if (v.z() > 0 || p.z() > zr + 1e-9) {
        airborne = true;
        start_flight(t);
      }
    }
    if (airborne) {
      // RK4 step; at a ground crossing, interpolate the contact and bounce.
      const Eigen::Vector3d a1 = accel(v);
      const Eigen::Vector3d a2 = accel(v + 0.5 * dt_ * a1);
      const Eigen::Vector3d a3 = accel(v + 0.5 * dt_ * a2);
      const Eigen::Vector3d a4 = accel(v + dt_ * a3);
      const Eigen::Vector3d v1 = v + 0.5 * dt_ * a1, v2 = v + 0.5 * dt_ * a2, v3 = v + dt_ * a3;
      Eigen::Vector3d pn = p + dt_ / 6 * (v + 2 * v1 + 2 * v2 + v3);
      Eigen::Vector3d vn = v + dt_ / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
      if (pn.z() <= zr && vn.z() < 0) {
        // Contact inside this step: move to it, bounce, continue the rest of the step.
        const double f = (p.z() - zr) / (p.z() - pn.z());
        Eigen::Vector3d pc = p + f * (pn - p);
        Eigen::Vector3d vc = v + f * (vn - v);
        pc.z() = zr;
        p = pc;
        v = vc;
        const double tc = t + f * dt_;
        end_flight(tc, true);
        const double vz_after = -o.restitution * v.z();
        v.head<2>() *= o.tangential_factor;
        if (vz_after < o.min_bounce_mps) {
          v.z() = 0;
          airborne = false;
        } else {
          v.z() = vz_after;
          start_flight(tc);
        }
        const double rest = (1 - f) * dt_;
        p += v * rest;
        if (airborne) {
          p.z() -= 0.5 * o.gravity_mps2 * rest * rest;
          v.z() -= o.gravity_mps2 * rest;
        }
      } else {
        p = pn;
        v = vn;
      }
      if (in_flight && p.z() > cur.apex_m.z()) cur.apex_m = p;
    } else {
      // Rolling with constant deceleration.
      const double speed = v.head<2>().norm();
      if (speed > 0) {
        const double ns = std::max(0.0, speed - o.rolling_decel_mps2 * dt_);
        p.head<2>() += 0.5 * (speed + ns) * dt_ * v.head<2>() / speed;
        v.head<2>() *= ns / speed;
      }
      v.z() = 0;
      p.z() = zr;
    }
    positions_.push_back(p);
  }
  end_flight(steps * dt_, false);
}

Eigen::Vector3d BallSimulation::BallAt(double time_s) const {
  const double x = std::clamp(time_s / dt_, 0.0, static_cast<double>(positions_.size() - 1));
  const size_t i = std::min(static_cast<size_t>(x), positions_.size() - 2);
  const double f = x - i;
  return (1 - f) * positions_[i] + f * positions_[i + 1];
}

std::vector<BallSample> BallSimulation::Sample(double fps, double noise_m, double dropout,
                                               double outlier_rate, double outlier_m,
                                               util::Rng& rng, double t0_s) const {
  CheckPositive(fps, "fps");
  std::vector<BallSample> out;
  const int frames = static_cast<int>(std::floor((options_.duration_s - t0_s) * fps));
  for (int f = 0; f < frames; ++f) {
    const double t = t0_s + f / fps;
    if (rng.Uniform() < dropout) continue;
    BallSample s;
    s.frame = f;
    s.time_s = t;
    s.n_cams = 2;
    // One draw per statement, z first: the arguments of one call are evaluated in an unspecified
    // order (GCC right to left, clang left to right); GCC's order keeps the samples so far and
    // gives clang the same.
    Eigen::Vector3d e;
    for (int a = 2; a >= 0; --a) e[a] = rng.Normal(0, noise_m);
    s.ball_in_world = BallAt(t) + e;
    if (rng.Uniform() < outlier_rate) {
      Eigen::Vector3d d;
      for (int a = 2; a >= 0; --a) d[a] = rng.Normal();
      s.ball_in_world += outlier_m * d.normalized();
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace fv::recon
