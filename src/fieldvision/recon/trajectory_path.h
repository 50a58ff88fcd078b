// One flight's integrated path at every sample time of a fit, for the drag and spin models: the
// positions and their derivatives by the 10 parameters (p0, v0, drag k, Magnus vector s; Ceres
// Jets through trajectory_physics.h's RK4) from one sweep forward and one backward from the
// reference time, instead of one integration from the reference time per sample (O(span) per
// evaluation instead of O(samples x span)). FlightResiduals are all samples' residuals, each under
// its own robust loss, in one Ceres block.
#pragma once

#include <vector>

#include <ceres/cost_function.h>
#include <ceres/sized_cost_function.h>
#include <Eigen/Core>

#include "fieldvision/camera/camera.h"
#include "fieldvision/recon/triangulation_internal.h"

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
  template <int L>  // derivative lanes: 0 (values), 4 (v0, k) or 7 (v0, k, s)
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

// The residuals of all samples of a fit in one block (parameter blocks p0 3, v0 3, k 1, s 3), each
// sample under its own Huber loss (scale huber_m) as Ceres applies one to a residual block: a
// sample's position error scaled by sqrt(rho') (Ceres's Corrector for a loss with rho'' <= 0, as
// the Huber loss always has), and one last row sqrt(sum of rho - rho' |r|^2) with a zero Jacobian
// that makes the block's cost 0.5 sum rho(|r|^2). The same problem, steps and optimum as a
// residual block with a HuberLoss per sample, without Ceres's work per block (most of a small
// fit's time). `path` nullptr: the drag-free parabola in closed form, else the integrated path.
class FlightResiduals : public ceres::CostFunction {
 public:
  FlightResiduals(FlightPath* path, std::vector<double> dt_s, std::vector<Eigen::Vector3d> x_m,
                  double gravity_mps2, double huber_m);
  bool Evaluate(const double* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  FlightPath* path_;
  std::vector<double> dt_;
  std::vector<Eigen::Vector3d> x_;
  double g_, huber_;
};

// One camera's detection of a flight: the pixel where the camera sees the flight's position at
// the detection's time (sample `index` of `path`, or the drag-free parabola at dt_s when `path`
// is null) minus the detection, in units of sigma_px; parameter blocks p0 3, v0 3, k 1, s 3. The
// blocks of one fit share their path, which integrates once per parameter values: O(span) per
// evaluation against O(samples x span) for a Jet integration per block. Ceres must evaluate the
// blocks one after another (Solver::Options::num_threads 1, its default).
class FlightReprojection : public ceres::SizedCostFunction<2, 3, 3, 1, 3> {
 public:
  FlightReprojection(FlightPath* path, int index, double dt_s, double gravity_mps2,
                     const camera::Camera& camera, const Eigen::Vector2d& uv_px, double sigma_px);
  bool Evaluate(const double* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  FlightPath* path_;
  int index_;
  double dt_, g_;
  detail::CameraBlock camera_;
  Eigen::Vector2d uv_;
  double sigma_;
};

}  // namespace fv::recon
