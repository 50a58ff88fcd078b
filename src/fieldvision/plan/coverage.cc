#include "fieldvision/plan/coverage.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <ceres/jet.h>
#include <fmt/format.h>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"
#include "fieldvision/util/stats.h"

namespace fv::plan {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

bool HasDistortion(const camera::Camera& c) {
  for (double d : c.distortion) {
    if (d != 0.0) return true;
  }
  return false;
}

void ComputeStatistics(const CoverageOptions& o, int num_cameras, CoverageLayer& layer) {
  const size_t n = layer.size();
  layer.fraction_exactly.assign(num_cameras + 1, 0.0);
  std::vector<double> angles, errors, axes;
  size_t at_least_2 = 0, good = 0;
  for (size_t c = 0; c < n; ++c) {
    layer.fraction_exactly[layer.count[c]] += 1.0;
    if (layer.count[c] < 2) continue;
    ++at_least_2;
    const double a = layer.best_angle_deg[c];
    angles.push_back(a);
    if (a >= o.good_angle_min_deg && a <= o.good_angle_max_deg) {
      ++good;
      if (std::isfinite(layer.err_rms_m[c])) {
        errors.push_back(layer.err_rms_m[c]);
        axes.push_back(layer.err_max_axis_m[c]);
      }
    }
  }
  for (double& f : layer.fraction_exactly) f /= n;
  layer.fraction_at_least_2 = static_cast<double>(at_least_2) / n;
  layer.fraction_good = static_cast<double>(good) / n;
  layer.angle_median_deg = angles.empty() ? NAN : util::RankPercentile(angles, 0.5);
  layer.fraction_angle_good_of_2 = at_least_2 > 0 ? static_cast<double>(good) / at_least_2 : NAN;
  layer.err_median_m = errors.empty() ? NAN : util::RankPercentile(errors, 0.5);
  layer.err_p95_m = errors.empty() ? NAN : util::RankPercentile(errors, 0.95);
  layer.err_max_m = errors.empty() ? NAN : *std::max_element(errors.begin(), errors.end());
  layer.err_max_axis_max_m = axes.empty() ? NAN : *std::max_element(axes.begin(), axes.end());
  layer.score = layer.fraction_good -
                o.error_weight_per_m * (std::isfinite(layer.err_max_m) ? layer.err_max_m : 0.0);
}

}  // namespace

void CoverageOptions::Check() const {
  CheckPositive(grid_step_m, "grid_step_m");
  CheckPositive(ball_diameter_m, "ball_diameter_m");
  CheckNonNegative(height_above_m, "height_above_m");
  CheckNonNegative(min_ball_px, "min_ball_px");
  CheckNonNegative(margin_px, "margin_px");
  CheckPositive(pixel_noise_px, "pixel_noise_px");
  CheckInRange(good_angle_min_deg, 0, 180, "good_angle_min_deg");
  CheckInRange(good_angle_max_deg, 0, 180, "good_angle_max_deg");
  FV_REQUIRE(good_angle_min_deg <= good_angle_max_deg,
             "good_angle_min_deg ({}) must not exceed good_angle_max_deg ({})", good_angle_min_deg,
             good_angle_max_deg);
  CheckNonNegative(error_weight_per_m, "error_weight_per_m");
}

void CheckCoverageGrid(const field::FieldModel& field, const CoverageOptions& options,
                       std::string_view what) {
  const double half_x =
      options.include_surround ? field.HalfLengthWithSurround() : 0.5 * field.length_m;
  const double half_y =
      options.include_surround ? field.HalfWidthWithSurround() : 0.5 * field.width_m;
  constexpr double kMaxCells = 4e6;  // a 2 km x 2 km area at 1 m, a football pitch at 6 cm
  FV_REQUIRE(
      (2 * half_x / options.grid_step_m) * (2 * half_y / options.grid_step_m) <= kMaxCells,
      "coverage: {} {} m gives more than {:.0f} cells on field '{}' ({:.0f} x {:.0f} m): use "
      "a larger step",
      what, options.grid_step_m, kMaxCells, field.name, 2 * half_x, 2 * half_y);
}

bool SeesPoint(const camera::Camera& camera, const Eigen::Vector3d& p_world,
               const CoverageOptions& options) {
  const Eigen::Vector3d p_cam = camera.cam_from_world * p_world;
  if (!(p_cam.z() > 0)) return false;
  const auto uv = camera.ProjectFromCamera(p_cam);
  if (!uv || !camera.InImage(*uv, options.margin_px)) return false;
  if (options.min_ball_px > 0) {
    // Its image's narrowest width: the focal length times the diameter over the depth along the
    // optical axis (over the distance it was 1 / cos(off-axis angle) too small: 8.2 px for the
    // render's 9.6-10.1 px 32 degrees off the axis, and corners the cameras see were counted
    // unseen), times the lens distortion's smallest magnification there (a wide barrel lens
    // shrinks a ball near its border).
    double diameter_px = std::sqrt(camera.fx * camera.fy) * options.ball_diameter_m / p_cam.z();
    if (HasDistortion(camera)) {
      diameter_px *= camera.DistortionMinScale(p_cam.head<2>() / p_cam.z());
    }
    if (!(diameter_px >= options.min_ball_px)) return false;
  }
  if (HasDistortion(camera)) {
    // Strong distortion folds points far outside the view back into the image: keep a point only
    // where undistorting its pixel gives its own direction back.
    const auto xn = camera.Undistort(*uv);
    if (!xn) return false;
    const Eigen::Vector2d expected(p_cam.x() / p_cam.z(), p_cam.y() / p_cam.z());
    if ((*xn - expected).norm() > 1e-6 * (1.0 + expected.norm())) return false;
  }
  return true;
}

double RayAngleDeg(const Eigen::Vector3d& centre_a, const Eigen::Vector3d& centre_b,
                   const Eigen::Vector3d& p_world) {
  const Eigen::Vector3d a = (centre_a - p_world).normalized();
  const Eigen::Vector3d b = (centre_b - p_world).normalized();
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
}

std::optional<Eigen::Matrix<double, 2, 3>> ProjectionJacobian(const camera::Camera& camera,
                                                              const Eigen::Vector3d& p_world) {
  if (!HasDistortion(camera)) {
    // Pinhole: d(uv)/d(p_cam) = [fx / Z, 0, -fx X / Z^2; 0, fy / Z, -fy Y / Z^2], times R.
    const Eigen::Vector3d q = camera.cam_from_world * p_world;
    if (!(q.z() > 0)) return std::nullopt;
    Eigen::Matrix<double, 2, 3> d;
    d << camera.fx / q.z(), 0, -camera.fx * q.x() / (q.z() * q.z()), 0, camera.fy / q.z(),
        -camera.fy * q.y() / (q.z() * q.z());
    return d * camera.cam_from_world.rotation;
  }
  using Jet = ceres::Jet<double, 3>;
  const auto intr = camera.IntrinsicsBlock();
  std::array<Jet, camera::kNumIntrinsics> intr_jet;
  for (int i = 0; i < camera::kNumIntrinsics; ++i) intr_jet[i] = Jet(intr[i]);
  const Eigen::Matrix3d& r = camera.cam_from_world.rotation;
  const Eigen::Vector3d& t = camera.cam_from_world.translation;
  Jet p_cam[3];
  for (int row = 0; row < 3; ++row) {
    p_cam[row] =
        Jet(r(row, 0) * p_world.x() + r(row, 1) * p_world.y() + r(row, 2) * p_world.z() + t(row));
    for (int col = 0; col < 3; ++col) p_cam[row].v[col] = r(row, col);
  }
  Jet uv[2];
  if (!camera::ProjectCameraPoint(intr_jet.data(), p_cam, uv)) return std::nullopt;
  Eigen::Matrix<double, 2, 3> j;
  j.row(0) = uv[0].v.transpose();
  j.row(1) = uv[1].v.transpose();
  return j;
}

namespace {

// Eigen-decomposition of the information matrix sum_i J_i^T J_i / sigma^2 of the point; nullopt
// when a camera cannot project it or the rays leave a direction unobserved.
std::optional<Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>> InformationEigen(
    const std::vector<const camera::Camera*>& cameras, const Eigen::Vector3d& p_world,
    double sigma_px) {
  if (cameras.size() < 2) return std::nullopt;
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  for (const camera::Camera* c : cameras) {
    const auto j = ProjectionJacobian(*c, p_world);
    if (!j) return std::nullopt;
    info += j->transpose() * *j;
  }
  info /= sigma_px * sigma_px;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(info);
  const Eigen::Vector3d ev = eig.eigenvalues();  // increasing
  if (!(ev(0) > 1e-10 * ev(2))) return std::nullopt;
  return eig;
}

}  // namespace

std::optional<Eigen::Matrix3d> TriangulationCovariance(
    const std::vector<const camera::Camera*>& cameras, const Eigen::Vector3d& p_world,
    double sigma_px) {
  const auto eig = InformationEigen(cameras, p_world, sigma_px);
  if (!eig) return std::nullopt;
  return eig->eigenvectors() * eig->eigenvalues().cwiseInverse().asDiagonal() *
         eig->eigenvectors().transpose();
}

CoverageResult EvaluateCoverage(const std::vector<camera::Camera>& cameras,
                                const field::FieldModel& field, const CoverageOptions& options) {
  options.Check();
  FV_REQUIRE(!cameras.empty(), "coverage: no cameras");
  for (const camera::Camera& c : cameras) {
    c.Check("coverage: camera '" + c.name + "'");
    FV_REQUIRE(c.has_pose, "coverage: camera '{}' has no pose", c.name);
  }
  const auto start = std::chrono::steady_clock::now();
  CoverageResult result;
  result.options = options;
  result.num_cameras = static_cast<int>(cameras.size());
  const double half_x =
      options.include_surround ? field.HalfLengthWithSurround() : 0.5 * field.length_m;
  const double half_y =
      options.include_surround ? field.HalfWidthWithSurround() : 0.5 * field.width_m;
  FV_REQUIRE(half_x > 0 && half_y > 0, "coverage: field '{}' has no area", field.name);
  std::vector<double> heights = {0.5 * options.ball_diameter_m};
  if (options.height_above_m > 0) heights.push_back(heights[0] + options.height_above_m);

  CheckCoverageGrid(field, options);
  const int nx = std::max(1, static_cast<int>(std::lround(2 * half_x / options.grid_step_m)));
  const int ny = std::max(1, static_cast<int>(std::lround(2 * half_y / options.grid_step_m)));
  std::vector<Eigen::Vector3d> centres;
  centres.reserve(cameras.size());
  for (const camera::Camera& c : cameras) centres.push_back(c.CentreInWorld());
  util::Progress progress("coverage", static_cast<long long>(heights.size()) * ny, "rows",
                          options.progress);
  long long rows_done = 0;
  std::vector<const camera::Camera*> seeing;
  for (double h : heights) {
    CoverageLayer layer;
    layer.height_m = h;
    layer.nx = nx;
    layer.ny = ny;
    layer.step_x_m = 2 * half_x / nx;
    layer.step_y_m = 2 * half_y / ny;
    layer.x0_m = -half_x + 0.5 * layer.step_x_m;
    layer.y0_m = -half_y + 0.5 * layer.step_y_m;
    const size_t n = static_cast<size_t>(nx) * ny;
    layer.count.assign(n, 0);
    layer.best_angle_deg.assign(n, NAN);
    layer.err_rms_m.assign(n, NAN);
    layer.err_max_axis_m.assign(n, NAN);
    std::vector<size_t> seeing_index;
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const size_t cell = static_cast<size_t>(j) * nx + i;
        const Eigen::Vector3d p = layer.CellCentre(i, j);
        seeing.clear();
        seeing_index.clear();
        for (size_t k = 0; k < cameras.size(); ++k) {
          if (SeesPoint(cameras[k], p, options)) {
            seeing.push_back(&cameras[k]);
            seeing_index.push_back(k);
          }
        }
        layer.count[cell] = static_cast<int>(seeing.size());
        if (seeing.size() < 2) continue;
        double best = NAN;
        for (size_t a = 0; a < seeing_index.size(); ++a) {
          for (size_t b = a + 1; b < seeing_index.size(); ++b) {
            const double angle = RayAngleDeg(centres[seeing_index[a]], centres[seeing_index[b]], p);
            if (std::isnan(best) || std::abs(angle - 90) < std::abs(best - 90)) best = angle;
          }
        }
        layer.best_angle_deg[cell] = best;
        if (const auto eig = InformationEigen(seeing, p, options.pixel_noise_px)) {
          // Cov = V diag(1 / lambda) V^T: trace = sum 1 / lambda, largest axis 1 / lambda_min.
          const Eigen::Vector3d ev = eig->eigenvalues();
          layer.err_rms_m[cell] = std::sqrt(ev.cwiseInverse().sum());
          layer.err_max_axis_m[cell] = std::sqrt(1.0 / ev(0));
        }
      }
      progress.Update(++rows_done);
    }
    ComputeStatistics(options, result.num_cameras, layer);
    result.layers.push_back(std::move(layer));
  }
  progress.Finish();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::string CoverageResult::Summary() const {
  std::string s;
  auto pct = [](double f) {
    return std::isfinite(f) ? fmt::format("{:5.1f} %", 100 * f) : "  -  ";
  };
  auto mm = [](double m) { return std::isfinite(m) ? fmt::format("{:.1f} mm", 1000 * m) : "-"; };
  for (size_t l = 0; l < layers.size(); ++l) {
    const CoverageLayer& L = layers[l];
    s += fmt::format("points at z = {:.2f} m{} ({} x {} grid, {:.2f} x {:.2f} m cells)\n",
                     L.height_m, l == 0 ? " (ball on the ground)" : "", L.nx, L.ny, L.step_x_m,
                     L.step_y_m);
    s += "  cameras seeing a point ";
    for (size_t k = 0; k < L.fraction_exactly.size(); ++k) s += fmt::format("{:>8d}", k);
    s += options.include_surround ? "\n  share of field+run-off " : "\n  share of the field     ";
    for (double f : L.fraction_exactly) s += fmt::format("{:>8s}", pct(f));
    s += fmt::format(
        "\n  seen by >= 2: {}   with a good pair angle: {}   median best angle {}\n",
        pct(L.fraction_at_least_2), pct(L.fraction_good),
        std::isfinite(L.angle_median_deg) ? fmt::format("{:.1f} deg", L.angle_median_deg) : "-");
    s += fmt::format(
        "  expected 3D error (RMS, {:.2f} px noise) where the angle is good ({:.0f}-{:.0f} "
        "deg): median {}, 95 % {}, worst {} (largest axis {})\n",
        options.pixel_noise_px, options.good_angle_min_deg, options.good_angle_max_deg,
        mm(L.err_median_m), mm(L.err_p95_m), mm(L.err_max_m), mm(L.err_max_axis_max_m));
    s += fmt::format("  score (good share - weight x worst error): {:.4f}\n", L.score);
  }
  if (layers.size() > 1) s += fmt::format("score (mean of the layers): {:.4f}\n", score());
  return s;
}

double CoverageResult::score() const {
  if (layers.empty()) return 0.0;
  double sum = 0;
  for (const CoverageLayer& L : layers) sum += L.score;
  return sum / static_cast<double>(layers.size());
}

}  // namespace fv::plan
