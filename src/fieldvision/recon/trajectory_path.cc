#include "fieldvision/recon/trajectory_path.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <numeric>

#include <ceres/jet.h>

#include "fieldvision/recon/trajectory_physics.h"

namespace fv::recon {
namespace {

// The parameter blocks' sizes and their first index in the 10 parameters.
constexpr int kBlockSize[4] = {3, 3, 1, 3};
constexpr int kBlockStart[4] = {0, 3, 6, 7};

// What the path must carry for the derivatives Ceres asks of a block over (p0, v0, k, s): none,
// all but those by s (held constant), or all.
FlightPath::Need NeedFor(double** jacobians) {
  bool derivatives = false;
  for (int b = 0; jacobians != nullptr && b < 4; ++b) derivatives |= jacobians[b] != nullptr;
  if (!derivatives) return FlightPath::Need::kValues;
  return jacobians[3] == nullptr ? FlightPath::Need::kNoSpin : FlightPath::Need::kAll;
}

// The drag-free parabola dt after the reference time (FlightPositionAt without integration) and
// its derivatives by the 10 parameters (p0 and v0 only).
Eigen::Vector3d ParabolaAt(const double* const* params, double dt, double g,
                           FlightPath::Jacobian* d) {
  Eigen::Vector3d p;
  d->setZero();
  for (int j = 0; j < 3; ++j) {
    p[j] = params[0][j] + params[1][j] * dt;
    (*d)(j, j) = 1.0;
    (*d)(j, 3 + j) = dt;
  }
  p[2] -= 0.5 * g * dt * dt;
  return p;
}

// Derivatives are carried only by v0 (lanes 0-2), k (3) and, when asked for, s (4-6): the
// acceleration does not depend on the position, so d position / d p0 is the identity and
// d velocity / d p0 zero. They are the lanes a ceres::Jet over all 10 parameters would carry
// through FlightRk4Step (trajectory_physics.h), here from the variational equations of the same
// RK4 steps (the same values, derivatives equal to rounding) at about half a Jet's work.

// a = -g z - k |v| v + s x v (FlightAccel's operations, the same values) and, for the L lanes,
// da = (d a / d v) dv + (d a / d k, d a / d s).
template <int L>
void AccelWithLanes(const double v[3], const double (&dv)[3][L], double k, const double s[3],
                    double g, double a[3], double (&da)[3][L]) {
  const double speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + 1e-12);
  const double ks = -k * speed;
  for (int i = 0; i < 3; ++i) a[i] = ks * v[i];
  a[0] = a[0] + (s[1] * v[2] - s[2] * v[1]);
  a[1] = a[1] + (s[2] * v[0] - s[0] * v[2]);
  a[2] = a[2] + (s[0] * v[1] - s[1] * v[0]);
  a[2] -= g;
  if constexpr (L > 0) {
    // d a / d v = -k (|v| I + v v^T / |v|) + [s]x.
    double A[3][3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) A[i][j] = -k * v[i] * v[j] / speed;
      A[i][i] += ks;
    }
    A[0][1] -= s[2], A[0][2] += s[1];
    A[1][0] += s[2], A[1][2] -= s[0];
    A[2][0] -= s[1], A[2][1] += s[0];
    for (int i = 0; i < 3; ++i) {
      for (int l = 0; l < L; ++l) {
        da[i][l] = A[i][0] * dv[0][l] + A[i][1] * dv[1][l] + A[i][2] * dv[2][l];
      }
      da[i][3] -= speed * v[i];  // d a / d k
    }
    if constexpr (L > 4) {  // d (s x v) / d s
      da[0][5] += v[2], da[0][6] -= v[1];
      da[1][4] -= v[2], da[1][6] += v[0];
      da[2][4] += v[1], da[2][5] -= v[0];
    }
  }
}

// One RK4 step of FlightRk4Step, with the lanes (dp, dv: d position, d velocity by the lanes).
template <int L>
void Rk4StepWithLanes(double p[3], double v[3], double (&dp)[3][L], double (&dv)[3][L], double k,
                      const double s[3], double g, double h) {
  double a1[3], a2[3], a3[3], a4[3], vt[3], v2[3], v3[3];
  double da1[3][L], da2[3][L], da3[3][L], da4[3][L], dvt[3][L], dv2[3][L], dv3[3][L];
  auto stage = [&](const double(&a)[3], const double(&da)[3][L], double f) {
    for (int i = 0; i < 3; ++i) {
      vt[i] = v[i] + f * h * a[i];
      for (int l = 0; l < L; ++l) dvt[i][l] = dv[i][l] + f * h * da[i][l];
    }
  };
  AccelWithLanes<L>(v, dv, k, s, g, a1, da1);
  stage(a1, da1, 0.5);
  AccelWithLanes<L>(vt, dvt, k, s, g, a2, da2);
  std::memcpy(v2, vt, sizeof(vt));
  std::memcpy(dv2, dvt, sizeof(dvt));
  stage(a2, da2, 0.5);
  AccelWithLanes<L>(vt, dvt, k, s, g, a3, da3);
  std::memcpy(v3, vt, sizeof(vt));
  std::memcpy(dv3, dvt, sizeof(dvt));
  stage(a3, da3, 1.0);
  AccelWithLanes<L>(vt, dvt, k, s, g, a4, da4);
  for (int i = 0; i < 3; ++i) {
    p[i] = p[i] + h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + vt[i]);
    v[i] = v[i] + h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
    for (int l = 0; l < L; ++l) {
      dp[i][l] = dp[i][l] + h / 6.0 * (dv[i][l] + 2.0 * dv2[i][l] + 2.0 * dv3[i][l] + dvt[i][l]);
      dv[i][l] = dv[i][l] + h / 6.0 * (da1[i][l] + 2.0 * da2[i][l] + 2.0 * da3[i][l] + da4[i][l]);
    }
  }
}

}  // namespace

FlightPath::FlightPath(std::vector<double> dt_s, double gravity_mps2)
    : dt_(std::move(dt_s)), g_(gravity_mps2) {
  order_.resize(dt_.size());
  std::iota(order_.begin(), order_.end(), 0);
  std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) { return dt_[a] < dt_[b]; });
  first_ahead_ = static_cast<int>(
      std::partition_point(order_.begin(), order_.end(), [&](int i) { return dt_[i] < 0; }) -
      order_.begin());
  pos_.assign(dt_.size(), Eigen::Vector3d::Zero());
  jac_.assign(dt_.size(), Jacobian::Zero());
}

void FlightPath::Update(const double* const* params, Need level) {
  double key[kParams];
  for (int b = 0; b < 4; ++b) {
    std::memcpy(key + kBlockStart[b], params[b], sizeof(double) * kBlockSize[b]);
  }
  if (valid_ && std::equal(key, key + kParams, key_) && level_ >= level) return;
  std::copy(key, key + kParams, key_);
  switch (level) {
    case Need::kValues:
      Integrate<0>(params);
      break;
    case Need::kNoSpin:
      Integrate<4>(params);
      break;
    default:
      Integrate<7>(params);
  }
  valid_ = true;
  level_ = level;
  ++sweeps_;
}

template <int L>
void FlightPath::Integrate(const double* const* params) {
  const double k = params[2][0];
  const double* s = params[3];
  // Forward through the samples at or after the reference time, then backward through the others,
  // each from the state at the sample before; in steps of at most kMaxStepS (PropagateFlight's).
  for (const bool ahead : {true, false}) {
    double p[3], v[3];
    constexpr int kLanes = std::max(L, 4);  // (unused without lanes)
    double dp[3][kLanes] = {}, dv[3][kLanes] = {};
    for (int j = 0; j < 3; ++j) {
      p[j] = params[0][j];
      v[j] = params[1][j];
      dv[j][j] = 1.0;  // d v / d v0
    }
    double t = 0.0;
    const int n = static_cast<int>(order_.size());
    const int begin = ahead ? first_ahead_ : first_ahead_ - 1;
    const int end = ahead ? n : -1;
    for (int q = begin; q != end; q += ahead ? 1 : -1) {
      const int i = order_[q];
      const double dt = dt_[i] - t;
      if constexpr (L == 0) {
        steps_ += PropagateFlight(p, v, k, s, g_, dt);
      } else {
        const int steps = std::max(1, static_cast<int>(std::ceil(std::abs(dt) / kMaxStepS)));
        for (int st = 0; st < steps; ++st) Rk4StepWithLanes<L>(p, v, dp, dv, k, s, g_, dt / steps);
        steps_ += steps;
      }
      t = dt_[i];
      for (int j = 0; j < 3; ++j) pos_[i][j] = p[j];
      if constexpr (L > 0) {
        Jacobian& d = jac_[i];
        d.setZero();
        for (int j = 0; j < 3; ++j) {
          d(j, j) = 1.0;  // d p / d p0
          for (int lane = 0; lane < L; ++lane) d(j, 3 + lane) = dp[j][lane];
        }
      }
    }
  }
}

FlightResiduals::FlightResiduals(FlightPath* path, std::vector<double> dt_s,
                                 std::vector<Eigen::Vector3d> x_m, double gravity_mps2,
                                 double huber_m)
    : path_(path), dt_(std::move(dt_s)), x_(std::move(x_m)), g_(gravity_mps2), huber_(huber_m) {
  set_num_residuals(3 * static_cast<int>(x_.size()) + 1);
  *mutable_parameter_block_sizes() = {3, 3, 1, 3};
}

bool FlightResiduals::Evaluate(const double* const* parameters, double* residuals,
                               double** jacobians) const {
  const FlightPath::Need need = NeedFor(jacobians);
  const bool derivatives = need != FlightPath::Need::kValues;
  if (path_ != nullptr) path_->Update(parameters, need);
  const double b2 = huber_ * huber_;
  FlightPath::Jacobian d;
  const int n = static_cast<int>(x_.size());
  double rest2 = 0.0;  // sum of rho - rho' |r|^2
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p =
        path_ != nullptr ? path_->Position(i) : ParabolaAt(parameters, dt_[i], g_, &d);
    double r[3];
    for (int j = 0; j < 3; ++j) r[j] = p[j] - x_[i][j];
    // ceres::HuberLoss::Evaluate and ceres::internal::Corrector (rho'' <= 0: rows times
    // sqrt(rho')).
    const double sq = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    double scale = 1.0;
    if (sq > b2) {
      const double norm = std::sqrt(sq);
      const double rho0 = 2.0 * huber_ * norm - b2;
      const double rho1 = std::max(std::numeric_limits<double>::min(), huber_ / norm);
      scale = std::sqrt(rho1);
      rest2 += std::max(0.0, rho0 - rho1 * sq);
    }
    for (int j = 0; j < 3; ++j) residuals[3 * i + j] = scale * r[j];
    if (!derivatives) continue;
    if (path_ != nullptr) d = path_->Derivatives(i);
    for (int b = 0; b < 4; ++b) {
      if (jacobians[b] == nullptr) continue;
      double* rows = jacobians[b] + ptrdiff_t{3} * i * kBlockSize[b];
      for (int j = 0; j < 3; ++j) {
        for (int c = 0; c < kBlockSize[b]; ++c) {
          rows[j * kBlockSize[b] + c] = scale * d(j, kBlockStart[b] + c);
        }
      }
    }
  }
  residuals[ptrdiff_t{3} * n] = std::sqrt(rest2);
  for (int b = 0; derivatives && b < 4; ++b) {
    if (jacobians[b] == nullptr) continue;
    for (int c = 0; c < kBlockSize[b]; ++c) {
      jacobians[b][ptrdiff_t{3} * n * kBlockSize[b] + c] = 0.0;
    }
  }
  return true;
}

FlightReprojection::FlightReprojection(FlightPath* path, int index, double dt_s,
                                       double gravity_mps2, const camera::Camera& camera,
                                       const Eigen::Vector2d& uv_px, double sigma_px)
    : path_(path),
      index_(index),
      dt_(dt_s),
      g_(gravity_mps2),
      camera_(camera),
      uv_(uv_px),
      sigma_(sigma_px) {}

bool FlightReprojection::Evaluate(const double* const* parameters, double* residuals,
                                  double** jacobians) const {
  const FlightPath::Need need = NeedFor(jacobians);
  const bool derivatives = need != FlightPath::Need::kValues;
  FlightPath::Jacobian d;  // d position / d parameters
  Eigen::Vector3d p;
  if (path_ != nullptr) {
    path_->Update(parameters, need);
    p = path_->Position(index_);
    if (derivatives) d = path_->Derivatives(index_);
  } else {
    p = ParabolaAt(parameters, dt_, g_, &d);
  }
  // The projection and its derivatives by the position (forward mode over the 3 coordinates).
  using Jet3 = ceres::Jet<double, 3>;
  const Jet3 x[3] = {Jet3(p[0], 0), Jet3(p[1], 1), Jet3(p[2], 2)};
  Jet3 uv[2];
  if (!detail::PredictCentre(camera_, 0.0, x, uv)) return false;
  residuals[0] = (uv[0].a - uv_.x()) / sigma_;
  residuals[1] = (uv[1].a - uv_.y()) / sigma_;
  if (!derivatives) return true;
  Eigen::Matrix<double, 2, 3> duv_dx;
  duv_dx.row(0) = uv[0].v.transpose() / sigma_;
  duv_dx.row(1) = uv[1].v.transpose() / sigma_;
  const Eigen::Matrix<double, 2, FlightPath::kParams> j_all = duv_dx * d;
  for (int b = 0; b < 4; ++b) {
    if (jacobians[b] == nullptr) continue;
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < kBlockSize[b]; ++c) {
        jacobians[b][r * kBlockSize[b] + c] = j_all(r, kBlockStart[b] + c);
      }
    }
  }
  return true;
}

}  // namespace fv::recon
