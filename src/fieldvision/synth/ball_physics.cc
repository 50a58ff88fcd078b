#include "fieldvision/synth/ball_physics.h"

#include <algorithm>
#include <cmath>

namespace fv::synth {
namespace {

struct State {
  Eigen::Vector3d p, v;
};

class Dynamics {
 public:
  Dynamics(const BallPhysics& ph, double radius_m) : ph_(ph), r_(radius_m) {
    const double area = M_PI * radius_m * radius_m;
    k_ = 0.5 * ph.air_density_kgm3 * ph.drag_coefficient * area / ph.mass_kg;
  }
  // Acceleration; `rolling` adds rolling resistance and removes gravity (the ground holds it).
  Eigen::Vector3d Accel(const Eigen::Vector3d& v, bool rolling) const {
    Eigen::Vector3d a = -k_ * v.norm() * v;
    if (rolling) {
      const double s = v.head<2>().norm();
      if (s > 1e-9) a.head<2>() -= ph_.rolling_resistance * ph_.gravity_mps2 * v.head<2>() / s;
      a.z() = 0;
    } else {
      a.z() -= ph_.gravity_mps2;
    }
    return a;
  }
  State Step(const State& s, double h, bool rolling) const {
    const Eigen::Vector3d k1v = Accel(s.v, rolling), k1p = s.v;
    const Eigen::Vector3d v2 = s.v + 0.5 * h * k1v;
    const Eigen::Vector3d k2v = Accel(v2, rolling);
    const Eigen::Vector3d& k2p = v2;
    const Eigen::Vector3d v3 = s.v + 0.5 * h * k2v;
    const Eigen::Vector3d k3v = Accel(v3, rolling);
    const Eigen::Vector3d& k3p = v3;
    const Eigen::Vector3d v4 = s.v + h * k3v;
    const Eigen::Vector3d k4v = Accel(v4, rolling);
    const Eigen::Vector3d& k4p = v4;
    return {s.p + h / 6.0 * (k1p + 2 * k2p + 2 * k3p + k4p),
            s.v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)};
  }
  double radius() const { return r_; }

 private:
  BallPhysics ph_;
  double r_;
  double k_;
};

}  // namespace

void BallTrajectory::Push(double t, const Eigen::Vector3d& p, const Eigen::Vector3d& v) {
  t_.push_back(t);
  p_.push_back(p);
  v_.push_back(v);
}

BallTrajectory::BallTrajectory(const BallSpec& ball, double end_time_s) {
  std::vector<KickSpec> kicks = ball.kicks;
  std::stable_sort(kicks.begin(), kicks.end(),
                   [](const KickSpec& a, const KickSpec& b) { return a.time_s < b.time_s; });
  if (kicks.empty()) {
    const Eigen::Vector3d p =
        ball.placements.empty() ? Eigen::Vector3d(0, 0, ball.radius_m()) : ball.placements[0];
    Push(0.0, p, Eigen::Vector3d::Zero());
    return;
  }
  const BallPhysics& ph = ball.physics;
  const Dynamics dyn(ph, ball.radius_m());
  const double r = ball.radius_m();
  const double h = ph.time_step_s;
  // Keep simulating past the end until the last flight has landed (bounded).
  const double hard_end = end_time_s + 30.0;

  State s{kicks[0].position_m, Eigen::Vector3d::Zero()};
  double t = kicks[0].time_s;
  Push(std::min(0.0, t), s.p, s.v);
  size_t next_kick = 0;
  bool airborne = false, rolling = false, resting = true;
  Flight flight;

  auto end_flight = [&](double te, const Eigen::Vector3d& p) {
    flight.t_end_s = te;
    flight.landing = p;
    if (flight.t_start_s < end_time_s) flights_.push_back(flight);
    airborne = false;
  };
  auto start_flight = [&](double ts, const State& st) {
    flight = Flight{};
    flight.t_start_s = ts;
    flight.origin = st.p;
    flight.v0_mps = st.v;
    flight.apex = st.p;
    airborne = true;
    rolling = resting = false;
  };
  auto settle = [&](State& st) {  // after a kick or a bounce: fly, roll or rest
    if (st.p.z() > r + 1e-9 || st.v.z() >= ph.min_bounce_speed_mps) {
      start_flight(t, st);
    } else {
      st.p.z() = r;
      st.v.z() = 0;
      rolling = st.v.head<2>().norm() > 1e-6;
      resting = !rolling;
      if (resting) st.v.setZero();
    }
  };

  while (true) {
    // Apply kicks due now.
    while (next_kick < kicks.size() && kicks[next_kick].time_s <= t + 1e-12) {
      if (airborne) end_flight(t, s.p);
      Push(t, s.p, s.v);  // the state just before the kick
      s.p = kicks[next_kick].position_m;
      s.v = kicks[next_kick].velocity_mps;
      Push(t, s.p, s.v);
      settle(s);
      ++next_kick;
    }
    const bool past_end = t >= end_time_s + h;
    if (past_end && !airborne && !rolling) break;
    if (t >= hard_end) {
      if (airborne) end_flight(t, s.p);
      break;
    }
    double step = h;
    if (next_kick < kicks.size()) step = std::min(step, kicks[next_kick].time_s - t);
    if (step <= 0) step = h;
    if (resting) {
      t += step;
      Push(t, s.p, s.v);
      continue;
    }
    State n = dyn.Step(s, step, rolling);
    if (airborne && n.p.z() < r) {
      // Locate the contact by bisection on the step length.
      double lo = 0, hi = step;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (dyn.Step(s, mid, false).p.z() < r) {
          hi = mid;
        } else {
          lo = mid;
        }
      }
      State c = dyn.Step(s, hi, false);
      c.p.z() = r;
      t += hi;
      Push(t, c.p, c.v);
      end_flight(t, c.p);
      // Bounce.
      c.v.z() = -ph.restitution * c.v.z();
      c.v.head<2>() *= (1.0 - ph.bounce_friction);
      Push(t, c.p, c.v);
      s = c;
      settle(s);
      continue;
    }
    if (rolling) {
      n.p.z() = r;
      n.v.z() = 0;
      // Stops when the speed would reverse within the step.
      if (n.v.head<2>().dot(s.v.head<2>()) <= 0 ||
          n.v.head<2>().norm() < ph.rolling_resistance * ph.gravity_mps2 * step) {
        n.v.setZero();
        rolling = false;
        resting = true;
      }
    }
    if (airborne && n.p.z() > flight.apex.z()) flight.apex = n.p;
    s = n;
    t += step;
    Push(t, s.p, s.v);
  }
}

namespace {

// The samples i and j = i + 1 around time_s (t.front() < time_s < t.back()): the last sample with
// t <= time_s, so that at a contact the later (post-bounce) sample is used; s is time_s's share of
// the way from t[i] to t[j] (1 where they coincide).
struct Bracket {
  size_t i, j;
  double dt, s;
};

Bracket BracketOf(const std::vector<double>& t, double time_s) {
  const size_t i = std::upper_bound(t.begin(), t.end(), time_s) - t.begin() - 1;
  const double dt = t[i + 1] - t[i];
  return {i, i + 1, dt, dt > 0 ? (time_s - t[i]) / dt : 1.0};
}

}  // namespace

Eigen::Vector3d BallTrajectory::PositionAt(double time_s) const {
  if (time_s <= t_.front()) return p_.front();
  if (time_s >= t_.back()) return p_.back();
  const auto [i, j, dt, s] = BracketOf(t_, time_s);
  if (dt <= 0) return p_[j];
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2,
               h11 = s3 - s2;
  return h00 * p_[i] + h10 * dt * v_[i] + h01 * p_[j] + h11 * dt * v_[j];
}

Eigen::Vector3d BallTrajectory::VelocityAt(double time_s) const {
  if (time_s <= t_.front()) return v_.front();
  if (time_s >= t_.back()) return v_.back();
  const auto [i, j, dt, s] = BracketOf(t_, time_s);
  if (dt <= 0) return v_[j];
  return (1 - s) * v_[i] + s * v_[j];
}

}  // namespace fv::synth
