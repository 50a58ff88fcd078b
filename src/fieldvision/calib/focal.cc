#include "fieldvision/calib/focal.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/camera/projection.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::calib {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Parameters x = f, k1, rvec[3], tvec[3]; principal point fixed.
struct FocalPointCost {
  FocalPointCost(double cx, double cy, const Eigen::Vector2d& uv, const Eigen::Vector3d& p)
      : cx(cx), cy(cy), uv(uv), p(p) {}
  template <typename T>
  bool operator()(const T* x, T* residual) const {
    T intr[camera::kNumIntrinsics];
    for (auto& v : intr) v = T(0);
    intr[0] = x[0];
    intr[1] = x[0];
    intr[2] = T(cx);
    intr[3] = T(cy);
    intr[4] = x[1];
    const T pw[3] = {T(p.x()), T(p.y()), T(p.z())};
    T uvp[2];
    if (!camera::ProjectWorldPoint(intr, x + 2, x + 5, pw, uvp)) return false;
    residual[0] = uvp[0] - T(uv.x());
    residual[1] = uvp[1] - T(uv.y());
    return true;
  }
  double cx, cy;
  Eigen::Vector2d uv;
  Eigen::Vector3d p;
};

camera::Camera CameraFromParams(int width, int height, const std::array<double, 8>& x) {
  camera::Camera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = x[0];
  c.cx = 0.5 * (width - 1);
  c.cy = 0.5 * (height - 1);
  c.distortion = {x[1], 0, 0, 0, 0};
  c.has_pose = true;
  c.cam_from_world = geometry::Rigid3d::FromRvecTvec({x[2], x[3], x[4]}, {x[5], x[6], x[7]});
  return c;
}

}  // namespace

void FocalOptions::Check() const {
  pnp.Check();
  FV_REQUIRE(min_hfov_deg > 1 && max_hfov_deg < 175 && min_hfov_deg < max_hfov_deg,
             "hfov range must be within (1, 175) deg and increasing (got {}..{})", min_hfov_deg,
             max_hfov_deg);
  FV_REQUIRE(hfov_steps >= 2, "hfov_steps must be >= 2 (got {})", hfov_steps);
  CheckPositive(outlier_px, "outlier_px");
  FV_REQUIRE(min_points >= 5, "min_points must be >= 5 (got {})", min_points);
  FV_REQUIRE(max_iterations >= 1, "max_iterations must be >= 1 (got {})", max_iterations);
  CheckPositive(max_focal_rel_std, "max_focal_rel_std");
}

std::string FocalResult::Summary() const {
  const Eigen::Vector3d& c = camera_position_m;
  std::string s = fmt::format(
      "focal {:.1f} px (std {:.1f} px, {:.1f}%), horizontal field of view {:.2f} deg (std {:.2f}); "
      "{}; camera at ({:.3f}, {:.3f}, {:.3f}) m (std {:.3f} {:.3f} {:.3f} m); "
      "{} of {} points inliers, rms {:.2f} px (noise estimate {:.2f} px)",
      camera.fx, std_focal_px, 100 * std_focal_px / camera.fx, hfov_deg, std_hfov_deg,
      std_k1 > 0 ? fmt::format("k1 {:.4f} (std {:.4f})", camera.distortion[0], std_k1)
                 : std::string("k1 not estimated"),
      c.x(), c.y(), c.z(), std_position_m.x(), std_position_m.y(), std_position_m.z(), num_inliers,
      points.size(), rms_px, residual_sigma_px);
  return s;
}

namespace {  // The stages of EstimateFocalAndPose.

// Starts: PnP at a sweep of fields of view; the most inliers, then the smallest error.
ExtrinsicsResult StartFromFovSweep(int width, int height,
                                   const std::vector<PointCorrespondence>& points,
                                   const FocalOptions& options) {
  bool have = false;
  ExtrinsicsResult best;
  std::string last_error;
  for (int i = 0; i < options.hfov_steps; ++i) {
    const double hfov = options.min_hfov_deg * std::pow(options.max_hfov_deg / options.min_hfov_deg,
                                                        i / (options.hfov_steps - 1.0));
    camera::Camera cam = camera::Camera::FromFov(width, height, hfov);
    try {
      ExtrinsicsResult e = EstimatePose(cam, points, options.pnp);
      if (!have || e.num_inliers > best.num_inliers ||
          (e.num_inliers == best.num_inliers && e.rms_px < best.rms_px)) {
        best = std::move(e);
        have = true;
      }
    } catch (const Error& e) {
      last_error = e.what();
      if (last_error.find("line") != std::string::npos) throw;  // degenerate input: say so
    }
  }
  FV_REQUIRE(have, "no focal length between {:.0f} and {:.0f} deg of view fits the points: {}",
             options.min_hfov_deg, options.max_hfov_deg, last_error);
  return best;
}

// The parameters x = f, k1, rvec, tvec and their fit to a subset of the points.
struct FocalFit {
  int width = 0, height = 0;
  const std::vector<PointCorrespondence>& points;
  const FocalOptions& options;
  std::array<double, 8> x{};

  ceres::Solver::Summary Solve(const std::vector<bool>& use, bool robust, ceres::Problem* problem) {
    const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
    for (size_t k = 0; k < points.size(); ++k) {
      if (!use[k]) continue;
      problem->AddResidualBlock(new ceres::AutoDiffCostFunction<FocalPointCost, 2, 8>(
                                    new FocalPointCost(cx, cy, points[k].uv_px, points[k].p_world)),
                                robust ? new ceres::HuberLoss(2.0) : nullptr, x.data());
    }
    if (!options.estimate_k1) problem->SetManifold(x.data(), new ceres::SubsetManifold(8, {1}));
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = options.max_iterations;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, problem, &summary);
    return summary;
  }
  std::vector<double> Errors() const {
    const camera::Camera c = CameraFromParams(width, height, x);
    std::vector<double> e(points.size());
    for (size_t k = 0; k < points.size(); ++k) {
      const auto uv = c.Project(points[k].p_world);
      e[k] = uv ? (*uv - points[k].uv_px).norm() : 1e9;
    }
    return e;
  }
  int Within(const std::vector<double>& e) const {
    int count = 0;
    for (double v : e) count += v <= options.outlier_px ? 1 : 0;
    return count;
  }
};

// The points to use (within the gate), after a robust fit. Points behind the start camera cannot
// be evaluated (gross outliers): left out at once. With few points one bad click bends even the
// robust fit and pushes good points over the gate: while some point is over it, refit leaving
// out each point in turn and keep the fit with the most points within the gate; then every point
// within the gate of that fit is used.
std::vector<bool> LeaveOutBadClicks(FocalFit* fit) {
  const int n = static_cast<int>(fit->points.size());
  std::vector<bool> use(n);
  const auto e0 = fit->Errors();
  for (int k = 0; k < n; ++k) use[k] = e0[k] < 1e9;
  ceres::Problem robust_problem;
  fit->Solve(use, true, &robust_problem);
  int n_in = static_cast<int>(std::count(use.begin(), use.end(), true));
  int best_in = fit->Within(fit->Errors());
  while (best_in < n_in && n_in > fit->options.min_points) {
    const std::array<double, 8> x_start = fit->x;
    std::array<double, 8> x_best = fit->x;
    int drop = -1;
    for (int k = 0; k < n; ++k) {
      if (!use[k]) continue;
      std::vector<bool> u = use;
      u[k] = false;
      fit->x = x_start;
      ceres::Problem refit;
      fit->Solve(u, true, &refit);
      const int in = fit->Within(fit->Errors());
      if (in > best_in) {
        best_in = in;
        x_best = fit->x;
        drop = k;
      }
    }
    fit->x = x_best;
    if (drop < 0) break;
    use[drop] = false;
    --n_in;
  }
  const auto e = fit->Errors();
  for (int k = 0; k < n; ++k) use[k] = e[k] <= fit->options.outlier_px;
  return use;
}

// Standard deviations of the focal length, k1, field of view and camera centre: (J^T J)^-1
// sigma^2 at the solution of `problem` (a fit without a robust loss).
void SetUncertainty(const std::array<double, 8>& x, int width, int dof, ceres::Problem* problem,
                    FocalResult* result) {
  result->std_focal_px = result->std_k1 = result->std_hfov_deg = kNaN;
  result->std_position_m.setConstant(kNaN);
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance covariance(co);
  std::vector<std::pair<const double*, const double*>> blocks = {{x.data(), x.data()}};
  if (dof <= 0 || !covariance.Compute(blocks, problem)) return;
  Eigen::Matrix<double, 8, 8, Eigen::RowMajor> cov;
  covariance.GetCovarianceBlock(x.data(), x.data(), cov.data());
  cov *= result->residual_sigma_px * result->residual_sigma_px;
  result->covariance_ok = true;
  result->std_focal_px = std::sqrt(std::max(0.0, cov(0, 0)));
  result->std_k1 = std::sqrt(std::max(0.0, cov(1, 1)));
  result->std_hfov_deg =
      (width / (x[0] * x[0] + 0.25 * width * width)) * result->std_focal_px * 180 / M_PI;
  // Camera centre C = -R(r)^T t: numerical Jacobian in (r, t).
  auto centre = [&](const Eigen::Matrix<double, 6, 1>& rt) {
    const Eigen::Matrix3d r = geometry::RotationFromRvec(rt.head<3>());
    return Eigen::Vector3d(-r.transpose() * rt.tail<3>());
  };
  Eigen::Matrix<double, 6, 1> rt;
  for (int k = 0; k < 6; ++k) rt[k] = x[2 + k];
  Eigen::Matrix<double, 3, 6> jac;
  for (int k = 0; k < 6; ++k) {
    const double h = 1e-6 * std::max(1.0, std::abs(rt[k]));
    Eigen::Matrix<double, 6, 1> a = rt, b = rt;
    a[k] += h;
    b[k] -= h;
    jac.col(k) = (centre(a) - centre(b)) / (2 * h);
  }
  const Eigen::Matrix3d cov_c = jac * cov.block<6, 6>(2, 2) * jac.transpose();
  for (int k = 0; k < 3; ++k) result->std_position_m[k] = std::sqrt(std::max(0.0, cov_c(k, k)));
}

void AddFocalWarnings(const FocalOptions& options, int n, FocalResult* result) {
  const double f = result->camera.fx;
  if (!result->covariance_ok) {
    result->warnings.push_back(
        "the focal length is not determined by these points (degenerate geometry: spread the "
        "points over the image and in depth, or use --homography-only for a flat field)");
  } else if (result->std_focal_px > options.max_focal_rel_std * f) {
    result->warnings.push_back(fmt::format(
        "the focal length is uncertain ({:.0f}% std): spread the points over the image and in "
        "depth, add points, or use --homography-only for a flat field",
        100 * result->std_focal_px / f));
  }
  if (result->num_inliers < n) {
    result->warnings.push_back(fmt::format(
        "{} points did not fit and were left out (marked 'outlier')", n - result->num_inliers));
  }
}

}  // namespace

FocalResult EstimateFocalAndPose(int width, int height,
                                 const std::vector<PointCorrespondence>& points,
                                 const FocalOptions& options) {
  options.Check();
  FV_REQUIRE(width > 0 && height > 0, "image size {}x{} is not valid (give --image-size WxH)",
             width, height);
  const int n = static_cast<int>(points.size());
  FV_REQUIRE(n >= options.min_points,
             "only {} points given; the focal length and the pose from one frame need at least {}",
             n, options.min_points);
  const ExtrinsicsResult start = StartFromFovSweep(width, height, points, options);
  FocalFit fit{width, height, points, options};
  fit.x[0] = start.camera.fx;
  const Eigen::Vector3d r0 = start.camera.cam_from_world.Rvec();
  for (int k = 0; k < 3; ++k) {
    fit.x[2 + k] = r0[k];
    fit.x[5 + k] = start.camera.cam_from_world.translation[k];
  }
  const std::vector<bool> use = LeaveOutBadClicks(&fit);
  const int n_in = static_cast<int>(std::count(use.begin(), use.end(), true));
  FV_REQUIRE(n_in >= options.min_points,
             "only {} of the {} points fit one camera within {:.1f} px; check the clicks and names",
             n_in, n, options.outlier_px);
  // Final fit without a robust loss (the inliers), so the covariance is the textbook one.
  ceres::Problem problem;
  const ceres::Solver::Summary summary = fit.Solve(use, false, &problem);
  const std::array<double, 8>& x = fit.x;
  FV_REQUIRE(summary.IsSolutionUsable() && x[0] > 0,
             "the focal length fit failed ({}); check the points", summary.message);

  FocalResult result;
  result.camera = CameraFromParams(width, height, x);
  result.camera.notes["intrinsics"] =
      fmt::format("from {} field points in one frame (principal point at the centre{})", n_in,
                  options.estimate_k1 ? ", k1 fitted" : "");
  result.camera_position_m = result.camera.CentreInWorld();
  result.hfov_deg = 2 * std::atan(0.5 * width / x[0]) * 180 / M_PI;
  result.points = PointResiduals(result.camera, points);
  double sq = 0;
  for (int k = 0; k < n; ++k) {
    result.points[k].inlier = use[k];
    if (use[k]) sq += result.points[k].err_px * result.points[k].err_px;
  }
  result.num_inliers = n_in;
  result.rms_px = std::sqrt(sq / n_in);
  const int dof = 2 * n_in - (options.estimate_k1 ? 8 : 7);
  result.residual_sigma_px = dof > 0 ? std::sqrt(sq / dof) : kNaN;
  SetUncertainty(x, width, dof, &problem, &result);
  AddFocalWarnings(options, n, &result);
  return result;
}

std::string HomographyResult::Summary() const {
  return fmt::format(
      "ground homography from {} of {} points: rms {:.2f} px in the image, {:.0f} mm on the field",
      num_inliers, points.size(), rms_px, rms_mm);
}

HomographyResult EstimateGroundHomography(int width, int height,
                                          const std::vector<PointCorrespondence>& points,
                                          double ransac_px) {
  FV_REQUIRE(width > 0 && height > 0, "image size {}x{} is not valid (give --image-size WxH)",
             width, height);
  CheckPositive(ransac_px, "ransac_px");
  FV_REQUIRE(points.size() >= 4, "only {} points given; a ground homography needs at least 4",
             points.size());
  std::vector<cv::Point2d> ground, image;
  for (const auto& p : points) {
    FV_REQUIRE(std::abs(p.p_world.z()) < 1e-6,
               "point '{}' is at z = {} m: the homography maps the ground (z = 0) only", p.name,
               p.p_world.z());
    ground.emplace_back(p.p_world.x(), p.p_world.y());
    image.emplace_back(p.uv_px.x(), p.uv_px.y());
  }
  cv::Mat mask;
  cv::Mat h;
  try {
    h = cv::findHomography(ground, image, cv::RANSAC, ransac_px, mask, 2000, 0.999);
  } catch (const cv::Exception&) {
    h.release();
  }
  FV_REQUIRE(!h.empty(),
             "no homography fits the {} ground points (on one line, or clicks in the wrong order?)",
             points.size());
  HomographyResult out;
  out.width = width;
  out.height = height;
  cv::cv2eigen(h, out.image_from_ground);
  const Eigen::Matrix3d ground_from_image = out.image_from_ground.inverse();
  double sq_px = 0, sq_mm = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    PointResidual r;
    r.name = points[i].name;
    r.uv_px = points[i].uv_px;
    r.p_world = points[i].p_world;
    const Eigen::Vector3d q = out.image_from_ground * Eigen::Vector3d(ground[i].x, ground[i].y, 1);
    r.projected_px = q.head<2>() / q.z();
    r.err_px = (r.projected_px - r.uv_px).norm();
    const Eigen::Vector3d g = ground_from_image * Eigen::Vector3d(r.uv_px.x(), r.uv_px.y(), 1);
    r.err_mm = 1000 * (g.head<2>() / g.z() - r.p_world.head<2>()).norm();
    r.inlier = mask.empty() || mask.at<uchar>(static_cast<int>(i)) != 0;
    if (r.inlier) {
      ++out.num_inliers;
      sq_px += r.err_px * r.err_px;
      sq_mm += *r.err_mm * *r.err_mm;
    }
    out.points.push_back(r);
  }
  out.rms_px = out.num_inliers ? std::sqrt(sq_px / out.num_inliers) : 0.0;
  out.rms_mm = out.num_inliers ? std::sqrt(sq_mm / out.num_inliers) : 0.0;
  return out;
}

void WriteHomographyYaml(const HomographyResult& h, const std::string& path) {
  util::AtomicWrite(
      path,
      [&](const std::string& tmp) {
        cv::FileStorage fs = camera::NewYamlWriter();
        cv::Mat m, inv;
        cv::eigen2cv(h.image_from_ground, m);
        const Eigen::Matrix3d g = h.image_from_ground.inverse();
        cv::eigen2cv(g, inv);
        fs << "image_width" << h.width << "image_height" << h.height;
        fs << "homography_image_from_ground" << m;
        fs << "homography_ground_from_image" << inv;
        fs << "rms_px" << h.rms_px << "rms_mm" << h.rms_mm;
        fs << "num_points" << static_cast<int>(h.points.size()) << "num_inliers" << h.num_inliers;
        camera::SaveYaml(fs, tmp, path, "homography file");
      },
      "homography file");
}

}  // namespace fv::calib
