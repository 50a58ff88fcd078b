// N views, refined: Ceres on the sigma-weighted reprojection error from the linear estimate,
// with the covariance (J^T J)^-1 of the point (Hartley & Zisserman sec. 5.2).
#include "fieldvision/recon/triangulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <ceres/ceres.h>
#include <fmt/format.h>
#include <Eigen/Dense>

#include "fieldvision/camera/sphere_image.h"
#include "fieldvision/recon/triangulation_internal.h"
#include "fieldvision/util/error.h"

namespace fv::recon::detail {

// Weighted reprojection residual of one view; `Ground` optimises x, y with z fixed.
template <bool Ground>
struct ReprojectionCost {
  ReprojectionCost(const CameraBlock& cam, const Eigen::Vector2d& obs, double sigma_px,
                   double radius_m, double z_m)
      : cam(cam), obs(obs), inv_sigma(1.0 / sigma_px), radius_m(radius_m), z_m(z_m) {}
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    const T p_world[3] = {p[0], p[1], Ground ? T(z_m) : p[2]};
    T uv[2];
    if (!PredictCentre(cam, radius_m, p_world, uv)) return false;
    residual[0] = (uv[0] - T(obs.x())) * T(inv_sigma);
    residual[1] = (uv[1] - T(obs.y())) * T(inv_sigma);
    return true;
  }
  CameraBlock cam;
  Eigen::Vector2d obs;
  double inv_sigma, radius_m, z_m;
};

// Refines `p` (3 values, or x, y when `ground`) on the views; fills residuals, rms, covariance.
void Refine(const std::vector<camera::Camera>& cameras, const std::vector<View>& views,
            const std::vector<int>& candidate_index, bool ground, const TriangulationOptions& o,
            Eigen::Vector3d* p, TriangulationResult* result) {
  double x[3] = {p->x(), p->y(), p->z()};
  ceres::Problem problem;
  std::vector<CameraBlock> blocks;
  blocks.reserve(views.size());
  for (const View& v : views) {
    blocks.emplace_back(cameras[v.camera]);
    if (ground) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ReprojectionCost<true>, 2, 2>(
              new ReprojectionCost<true>(blocks.back(), v.observation.centre_px,
                                         v.observation.sigma_px, ModelRadius(o), x[2])),
          nullptr, x);
    } else {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ReprojectionCost<false>, 2, 3>(
              new ReprojectionCost<false>(blocks.back(), v.observation.centre_px,
                                          v.observation.sigma_px, ModelRadius(o), 0.0)),
          nullptr, x);
    }
  }
  result->iterations = 0;
  if (o.refine) {
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = o.max_iterations;
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    so.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    result->iterations = static_cast<int>(summary.iterations.size());
    if (summary.IsSolutionUsable()) *p = Eigen::Vector3d(x[0], x[1], x[2]);
  }
  x[0] = p->x();
  x[1] = p->y();
  x[2] = p->z();
  // Weighted residuals and Jacobian at the solution.
  ceres::CRSMatrix jac;
  std::vector<double> weighted;
  double cost = 0;
  const bool evaluated =
      problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, &weighted, nullptr, &jac);
  const int n = ground ? 2 : 3;
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(jac.num_rows, n);
  if (evaluated) {
    for (int r = 0; r < jac.num_rows; ++r) {
      for (int k = jac.rows[r]; k < jac.rows[r + 1]; ++k) j(r, jac.cols[k]) = jac.values[k];
    }
  }
  result->covariance.setZero();
  if (evaluated) {
    const Eigen::MatrixXd jtj = j.transpose() * j;
    Eigen::FullPivLU<Eigen::MatrixXd> lu(jtj);
    if (lu.isInvertible()) result->covariance.topLeftCorner(n, n) = lu.inverse();
  }
  result->views.clear();
  double sum2 = 0;
  for (size_t i = 0; i < views.size(); ++i) {
    const View& v = views[i];
    ViewResidual vr;
    vr.camera = v.camera;
    vr.candidate = candidate_index.empty() ? 0 : candidate_index[i];
    if (evaluated && weighted.size() >= 2 * (i + 1)) {
      vr.residual_px =
          Eigen::Vector2d(weighted[2 * i], weighted[2 * i + 1]) * v.observation.sigma_px;
    } else if (auto uv = PredictBallCentre(cameras[v.camera], *p, ModelRadius(o))) {
      vr.residual_px = *uv - v.observation.centre_px;
    } else {
      vr.residual_px = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    }
    vr.err_px = vr.residual_px.norm();
    sum2 += vr.err_px * vr.err_px;
    result->views.push_back(vr);
  }
  std::sort(result->views.begin(), result->views.end(),
            [](const ViewResidual& a, const ViewResidual& b) { return a.camera < b.camera; });
  result->rms_px = views.empty() ? 0.0 : std::sqrt(sum2 / views.size());
  result->point_world = *p;
}

// The views with each centre's sigma grown by its radius' unexplained difference from the one
// expected at `p` (TriangulationOptions::radius_sigma_factor); nullopt when none differs.
std::optional<std::vector<View>> SizeWeightedViews(const std::vector<camera::Camera>& cameras,
                                                   const std::vector<View>& views,
                                                   const Eigen::Vector3d& p,
                                                   const TriangulationOptions& o) {
  if (o.radius_sigma_factor <= 0 || o.ball_radius_m <= 0) return std::nullopt;
  std::vector<View> out = views;
  bool changed = false;
  for (View& v : out) {
    if (v.observation.radius_px <= 0) continue;
    const auto expected = camera::SphereRadiusPx(cameras[v.camera], p, o.ball_radius_m);
    if (!expected) continue;
    const double excess = std::abs(v.observation.radius_px - *expected) -
                          o.radius_tolerance * *expected - o.radius_tolerance_px;
    if (!(excess > 0)) continue;
    v.observation.sigma_px = std::hypot(v.observation.sigma_px, o.radius_sigma_factor * excess);
    changed = true;
  }
  if (!changed) return std::nullopt;
  return out;
}

TriangulationResult TriangulateViews(const std::vector<camera::Camera>& cameras,
                                     const std::vector<View>& views,
                                     const std::vector<int>& candidate_index,
                                     const TriangulationOptions& o) {
  TriangulationResult result;
  if (views.size() < 2) {
    result.status = TriangulationStatus::kTooFewViews;
    return result;
  }
  // Degenerate when every pair of rays is (nearly) parallel.
  std::vector<Eigen::Vector3d> dirs;
  for (const View& v : views) {
    auto ray = cameras[v.camera].RayFromPixel(v.observation.centre_px);
    if (!ray) {
      result.status = TriangulationStatus::kDegenerate;
      return result;
    }
    dirs.push_back(ray->direction);
  }
  double max_angle_deg = 0;
  for (size_t a = 0; a < dirs.size(); ++a) {
    for (size_t b = a + 1; b < dirs.size(); ++b) {
      const double c = std::clamp(dirs[a].dot(dirs[b]), -1.0, 1.0);
      max_angle_deg = std::max(max_angle_deg, std::acos(c) * kRadToDeg);
    }
  }
  if (max_angle_deg < o.min_angle_deg) {
    result.status = TriangulationStatus::kDegenerate;
    return result;
  }
  const auto linear = TriangulateLinear(cameras, views);
  if (!linear) {
    result.status = TriangulationStatus::kDegenerate;
    return result;
  }
  Eigen::Vector3d p = *linear;
  if (!InFrontOfAll(cameras, views, p, o.min_depth_m)) {
    result.status = TriangulationStatus::kBehindCamera;
    result.point_world = p;
    return result;
  }
  Refine(cameras, views, candidate_index, false, o, &p, &result);
  if (const auto weighted = SizeWeightedViews(cameras, views, p, o)) {
    Refine(cameras, *weighted, candidate_index, false, o, &p, &result);
  }
  result.status = InFrontOfAll(cameras, views, p, o.min_depth_m)
                      ? TriangulationStatus::kOk
                      : TriangulationStatus::kBehindCamera;
  return result;
}

}  // namespace fv::recon::detail

namespace fv::recon {

using detail::CheckCamera;
using detail::CheckObservation;
using detail::TriangulateViews;

TriangulationResult TriangulatePoint(const std::vector<camera::Camera>& cameras,
                                     const std::vector<View>& views,
                                     const TriangulationOptions& options) {
  options.Check();
  for (const View& v : views) {
    CheckCamera(cameras, v.camera);
    CheckObservation(v.observation, fmt::format("triangulation camera {}", v.camera));
  }
  return TriangulateViews(cameras, views, {}, options);
}

}  // namespace fv::recon
