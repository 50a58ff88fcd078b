// The flight model's equations of motion, templated on the scalar so that Ceres can
// differentiate them: a = -g z - k |v| v + s x v (gravity, quadratic drag, Magnus lift with the
// Magnus vector s = c_M w), integrated with classical fourth-order Runge-Kutta in steps of at
// most kMaxStepS (trajectory.h explains the model); and the zero-mean prior on the Magnus
// vector that every spin fit uses.
#pragma once

#include <algorithm>
#include <cmath>
#include <type_traits>

#include <Eigen/Core>

namespace fv::recon {

constexpr double kMaxStepS = 0.01;  // RK4 step

// a = -g z - k |v| v + s x v, with s = c_M w (the Magnus vector, 1/s). k and s may be of another
// scalar type than the state (plain numbers when no derivatives by them are wanted).
template <typename T, typename K, typename S>
void FlightAccel(const T v[3], const K& k, const S s[3], double g, T a[3]) {
  using std::sqrt;
  const T speed = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + T(1e-12));
  const T ks = -k * speed;
  for (int i = 0; i < 3; ++i) a[i] = ks * v[i];
  // A constant zero Magnus vector (a drag-only or drag-free model) adds only zeros.
  bool magnus = true;
  if constexpr (std::is_same_v<S, double>) magnus = s[0] != 0.0 || s[1] != 0.0 || s[2] != 0.0;
  if (magnus) {
    a[0] = a[0] + (s[1] * v[2] - s[2] * v[1]);
    a[1] = a[1] + (s[2] * v[0] - s[0] * v[2]);
    a[2] = a[2] + (s[0] * v[1] - s[1] * v[0]);
  }
  a[2] -= T(g);
}

template <typename T, typename K, typename S>
void FlightRk4Step(T p[3], T v[3], const K& k, const S s[3], double g, double h) {
  T a1[3], a2[3], a3[3], a4[3], vt[3];
  FlightAccel(v, k, s, g, a1);
  for (int i = 0; i < 3; ++i) vt[i] = v[i] + 0.5 * h * a1[i];
  FlightAccel(vt, k, s, g, a2);
  T v2[3] = {vt[0], vt[1], vt[2]};
  for (int i = 0; i < 3; ++i) vt[i] = v[i] + 0.5 * h * a2[i];
  FlightAccel(vt, k, s, g, a3);
  T v3[3] = {vt[0], vt[1], vt[2]};
  for (int i = 0; i < 3; ++i) vt[i] = v[i] + h * a3[i];
  FlightAccel(vt, k, s, g, a4);
  for (int i = 0; i < 3; ++i) {
    p[i] = p[i] + h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + vt[i]);
    v[i] = v[i] + h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
  }
}

// Propagates (p, v) by dt seconds (either sign); returns the number of RK4 steps.
template <typename T, typename K, typename S>
int PropagateFlight(T p[3], T v[3], const K& k, const S s[3], double g, double dt) {
  const int n = std::max(1, static_cast<int>(std::ceil(std::abs(dt) / kMaxStepS)));
  const double h = dt / n;
  for (int i = 0; i < n; ++i) FlightRk4Step(p, v, k, s, g, h);
  return n;
}

// The position `dt` seconds after (p0, v0): integrated with drag k and Magnus vector s, or, with
// `integrate` false, the drag-free parabola.
template <typename T>
void FlightPositionAt(const T p0[3], const T v0[3], const T& k, const T s[3], double g, double dt,
                      bool integrate, T p[3]) {
  if (integrate) {
    T v[3] = {v0[0], v0[1], v0[2]};
    for (int i = 0; i < 3; ++i) p[i] = p0[i];
    PropagateFlight(p, v, k, s, g, dt);
    return;
  }
  for (int i = 0; i < 3; ++i) p[i] = p0[i] + v0[i] * dt;
  p[2] -= T(0.5 * g * dt * dt);
}

// Zero-mean prior on the Magnus vector, r = W s with W = w_perp (I - d d^T) + w_along d d^T for
// the flight direction d: weak across the flight, tighter along it (that spin makes almost no
// force, so only the prior holds it).
struct SpinPrior {
  SpinPrior(const Eigen::Vector3d& dir, double w_perp, double w_along) {
    W_ = w_perp * (Eigen::Matrix3d::Identity() - dir * dir.transpose()) +
         w_along * dir * dir.transpose();
  }
  template <typename T>
  bool operator()(const T* sm, T* r) const {
    for (int i = 0; i < 3; ++i) {
      r[i] = T(W_(i, 0)) * sm[0] + T(W_(i, 1)) * sm[1] + T(W_(i, 2)) * sm[2];
    }
    return true;
  }
  Eigen::Matrix3d W_;
};

}  // namespace fv::recon
