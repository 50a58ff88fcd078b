#include "fieldvision/recon/trajectory_path.h"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <type_traits>

#include <ceres/jet.h>

#include "fieldvision/recon/trajectory_physics.h"

namespace fv::recon {
namespace {

// The parameter blocks' sizes and their first index in the 10 parameters.
constexpr int kBlockSize[4] = {3, 3, 1, 3};
constexpr int kBlockStart[4] = {0, 3, 6, 7};

// Derivatives are carried only by v0 (lanes 0-2), k (3) and, when asked for, s (4-6): the
// acceleration does not depend on the position, so d position / d p0 is the identity and
// d velocity / d p0 zero. These lanes are exactly those of a Jet over all 10 parameters (a Jet's
// lanes are computed independently), at 4 or 7 lanes instead of 10.
using DragJet = ceres::Jet<double, 4>;
using SpinJet = ceres::Jet<double, 7>;

double Value(double x) { return x; }
template <int N>
double Value(const ceres::Jet<double, N>& x) {
  return x.a;
}

// A parameter as the scalar type: a Jet carries the unit derivative of its lane.
template <typename T>
T Seed(double value, int lane) {
  if constexpr (std::is_same_v<T, double>) {
    return value;
  } else {
    return lane < T::DIMENSION ? T(value, lane) : T(value);
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
  if (valid_ && std::memcmp(key, key_, sizeof(key)) == 0 && level_ >= level) return;
  std::memcpy(key_, key, sizeof(key));
  switch (level) {
    case Need::kValues:
      Integrate<double, double>(params);
      break;
    case Need::kNoSpin:
      Integrate<DragJet, double>(params);
      break;
    default:
      Integrate<SpinJet, SpinJet>(params);
  }
  valid_ = true;
  level_ = level;
  ++sweeps_;
}

template <typename T, typename S>
void FlightPath::Integrate(const double* const* params) {
  const T k = Seed<T>(params[2][0], 3);
  S s[3];
  for (int j = 0; j < 3; ++j) s[j] = Seed<S>(params[3][j], 4 + j);
  // Forward through the samples at or after the reference time, then backward through the others,
  // each from the state at the sample before.
  for (const bool ahead : {true, false}) {
    T p[3], v[3];
    for (int j = 0; j < 3; ++j) {
      p[j] = T(params[0][j]);
      v[j] = Seed<T>(params[1][j], j);
    }
    double t = 0.0;
    const int n = static_cast<int>(order_.size());
    const int begin = ahead ? first_ahead_ : first_ahead_ - 1;
    const int end = ahead ? n : -1;
    for (int q = begin; q != end; q += ahead ? 1 : -1) {
      const int i = order_[q];
      steps_ += PropagateFlight(p, v, k, s, g_, dt_[i] - t);
      t = dt_[i];
      for (int j = 0; j < 3; ++j) pos_[i][j] = Value(p[j]);
      if constexpr (!std::is_same_v<T, double>) {
        Jacobian& d = jac_[i];
        d.setZero();
        for (int j = 0; j < 3; ++j) {
          d(j, j) = 1.0;  // d p / d p0
          for (int lane = 0; lane < T::DIMENSION; ++lane) d(j, 3 + lane) = p[j].v[lane];
        }
      }
    }
  }
}

bool FlightPathResidual::Evaluate(const double* const* parameters, double* residuals,
                                  double** jacobians) const {
  bool derivatives = false;
  for (int b = 0; jacobians != nullptr && b < 4; ++b) derivatives |= jacobians[b] != nullptr;
  path_->Update(parameters, !derivatives              ? FlightPath::Need::kValues
                            : jacobians[3] == nullptr ? FlightPath::Need::kNoSpin
                                                      : FlightPath::Need::kAll);
  const Eigen::Vector3d& p = path_->Position(i_);
  for (int j = 0; j < 3; ++j) residuals[j] = p[j] - x_[j];
  if (!derivatives) return true;
  const FlightPath::Jacobian& d = path_->Derivatives(i_);
  for (int b = 0; b < 4; ++b) {
    if (jacobians[b] == nullptr) continue;
    for (int j = 0; j < 3; ++j) {
      for (int c = 0; c < kBlockSize[b]; ++c) {
        jacobians[b][j * kBlockSize[b] + c] = d(j, kBlockStart[b] + c);
      }
    }
  }
  return true;
}

}  // namespace fv::recon
