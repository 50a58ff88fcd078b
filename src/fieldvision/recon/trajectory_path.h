// One flight's integrated path at every sample time of a fit, for the drag and spin models: the
// positions and their derivatives by the 10 parameters (p0, v0, drag k, Magnus vector s; Ceres
// Jets through trajectory_physics.h's RK4) from one sweep forward and one backward from the
// reference time, instead of one integration from the reference time per sample (O(span) per
// evaluation instead of O(samples x span)). FlightPathResidual is one sample's residual that reads
// the shared path, so that each sample keeps its own robust loss in Ceres.
#pragma once

#include <vector>

#include <ceres/sized_cost_function.h>
#include <Eigen/Core>

namespace fv::recon {

class FlightPath {
 public:
  static constexpr int kParams = 10;  // p0 (3), v0 (3), k (1), s (3)
  using Jacobian = Eigen::Matrix<double, 3, kParams, Eigen::RowMajor>;

  // dt_s: each sample's time minus the reference time (any order).
  FlightPath(std::vector<double> dt_s, double gravity_mps2);

  // What to compute: values only, derivatives by all but s (those by s are zero: s is held
  // constant), derivatives by all.
  enum class Need { kValues, kNoSpin, kAll };
  // The path for the parameter blocks p0[3], v0[3], k[1], s[3]; integrated again only when their
  // values change, or when more derivatives are asked for at these values.
  void Update(const double* const* params, Need level);
  const Eigen::Vector3d& Position(int i) const { return pos_[i]; }
  const Jacobian& Derivatives(int i) const { return jac_[i]; }  // d position / d parameters

  // Work done so far (for tests and benchmarks): paths integrated and RK4 steps taken.
  long long sweeps() const { return sweeps_; }
  long long steps() const { return steps_; }

 private:
  template <typename T, typename S>
  void Integrate(const double* const* params);

  std::vector<double> dt_;
  std::vector<int> order_;  // sample indices by increasing dt
  int first_ahead_ = 0;     // position in order_ of the first sample with dt >= 0
  double g_;
  double key_[kParams] = {};
  bool valid_ = false;
  Need level_ = Need::kValues;
  std::vector<Eigen::Vector3d> pos_;
  std::vector<Jacobian> jac_;
  long long sweeps_ = 0, steps_ = 0;
};

// Residual of sample i, position x_m, against the shared path (parameter blocks 3, 3, 1, 3).
class FlightPathResidual : public ceres::SizedCostFunction<3, 3, 3, 1, 3> {
 public:
  FlightPathResidual(FlightPath* path, int i, const Eigen::Vector3d& x_m)
      : path_(path), i_(i), x_(x_m) {}
  bool Evaluate(const double* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  FlightPath* path_;
  int i_;
  Eigen::Vector3d x_;
};

}  // namespace fv::recon
