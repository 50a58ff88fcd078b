#include "fieldvision/calib/rig_lines.h"

#include <algorithm>
#include <cmath>

#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>
#include <ceres/rotation.h>
#include <fmt/format.h>

#include "fieldvision/util/error.h"

namespace fv::calib {
namespace {

using Interpolator = ceres::BiCubicInterpolator<ceres::Grid2D<float, 1>>;

// One line pixel of one rig camera: its ray (centre and direction in the current world estimate,
// relative to a ground pivot o) moved by the correction (p_old - o = R (p_new - o) + t) and cut
// with the ground; the residual is the ground distance to the nearest line centreline.
struct RigLinePixelCost {
  RigLinePixelCost(const Eigen::Vector3d& centre, const Eigen::Vector3d& dir,
                   const Eigen::Vector2d& pivot, const LineDistanceMap* map,
                   const Interpolator* interp)
      : c_(centre), d_(dir), o_(pivot), map_(map), interp_(interp) {}

  template <typename T>
  bool operator()(const T* rvec, const T* tvec, T* residual) const {
    const T minus_r[3] = {-rvec[0], -rvec[1], -rvec[2]};
    const T d_old[3] = {T(d_.x()), T(d_.y()), T(d_.z())};
    const T c_rel[3] = {T(c_.x() - o_.x()) - tvec[0], T(c_.y() - o_.y()) - tvec[1],
                        T(c_.z()) - tvec[2]};
    T d[3], c[3];
    ceres::AngleAxisRotatePoint(minus_r, d_old, d);
    ceres::AngleAxisRotatePoint(minus_r, c_rel, c);
    if (!(d[2] < T(-1e-9)) || !(c[2] > T(0))) {
      residual[0] = T(map_->max_distance_m());
      return true;
    }
    const T s = -c[2] / d[2];
    const T x = c[0] + s * d[0] + T(o_.x());
    const T y = c[1] + s * d[1] + T(o_.y());
    T row, col;
    map_->ToGrid(x, y, &row, &col);
    interp_->Evaluate(row, col, residual);
    return true;
  }

  Eigen::Vector3d c_, d_;
  Eigen::Vector2d o_;
  const LineDistanceMap* map_;
  const Interpolator* interp_;
};

geometry::Rigid3d CorrectionFrom(const Eigen::Vector3d& rvec, const Eigen::Vector3d& tvec,
                                 const Eigen::Vector2d& pivot) {
  const Eigen::Matrix3d r = geometry::RotationFromRvec(rvec);
  const Eigen::Vector3d o(pivot.x(), pivot.y(), 0.0);
  return geometry::Rigid3d{r, o - r * o + tvec};
}

}  // namespace

std::string RigRefineResult::Summary() const {
  int cams = 0, total = 0;
  for (int n : num_line_pixels) {
    cams += n > 0 ? 1 : 0;
    total += n;
  }
  std::string s = fmt::format(
      "{}: {} line pixels in {} of {} cameras; rig moved {:.1f} mm (largest camera centre "
      "change), turned {:.3f} deg; {} iterations",
      accepted ? "rig refined" : "rig not refined (" + status + ")", total, cams, cameras.size(),
      1000 * moved_m, rotated_deg, iterations);
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (num_line_pixels[i] == 0) continue;
    s += fmt::format("\n  {}: before: {}; after: {}", cameras[i].name, before[i].Summary(),
                     after[i].Summary());
  }
  return s;
}

RigRefineResult RefineRigWithLinePixels(const std::vector<camera::Camera>& rig,
                                        const std::vector<std::vector<Eigen::Vector2d>>& pixels,
                                        const field::FieldModel& field,
                                        const RefineOptions& options) {
  options.Check();
  FV_REQUIRE(!rig.empty(), "the rig has no cameras");
  RequirePaintedLines(field);
  FV_REQUIRE(pixels.size() == rig.size(), "{} cameras but {} line pixel lists", rig.size(),
             pixels.size());
  RigRefineResult result;
  result.cameras = rig;
  result.num_line_pixels.assign(rig.size(), 0);
  result.before.resize(rig.size());
  // The rays of every line pixel in the current world estimate; the pivot is the mean of their
  // ground points (rotations about it barely move the seen field).
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> rays;
  Eigen::Vector2d pivot = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < rig.size(); ++i) {
    const camera::Camera& cam = rig[i];
    cam.Check("rig camera '" + cam.name + "'");
    FV_REQUIRE(cam.has_pose, "rig camera '{}' has no pose; place the rig first", cam.name);
    result.num_line_pixels[i] = static_cast<int>(pixels[i].size());
    if (pixels[i].empty()) continue;
    result.before[i] = LineError(cam, pixels[i], field, options.gate_m);
    const Eigen::Vector3d centre = cam.CentreInWorld();
    const Eigen::Matrix3d world_from_cam = cam.cam_from_world.rotation.transpose();
    for (const auto& uv : pixels[i]) {
      const auto xn = cam.Undistort(uv);
      if (!xn) continue;
      const Eigen::Vector3d d = world_from_cam * Eigen::Vector3d(xn->x(), xn->y(), 1.0);
      rays.emplace_back(centre, d);
      if (d.z() < -1e-9 && centre.z() > 0) {
        pivot += (centre - centre.z() / d.z() * d).head<2>();
      }
    }
  }
  result.after = result.before;
  if (rays.size() < 50) {
    result.status = fmt::format("only {} line pixels over the rig's cameras; need 50", rays.size());
    return result;
  }
  pivot /= static_cast<double>(rays.size());
  if (!pivot.allFinite() || pivot.norm() > 1e4) pivot.setZero();

  const LineDistanceMap map(field, options.lut_resolution_m, options.lut_max_distance_m);
  const ceres::Grid2D<float, 1> grid(map.values().data(), 0, map.rows(), 0, map.cols());
  const Interpolator interp(grid);
  Eigen::Vector3d rvec = Eigen::Vector3d::Zero(), tvec = Eigen::Vector3d::Zero();
  auto build = [&](ceres::Problem& problem, double scale) {
    for (const auto& [c, d] : rays) {
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<RigLinePixelCost, 1, 3, 3>(
                                   new RigLinePixelCost(c, d, pivot, &map, &interp)),
                               new ceres::CauchyLoss(scale), rvec.data(), tvec.data());
    }
  };
  const LossScaleSolve solve =
      SolveOverLossScales(build, options.loss_scales_m, options.max_iterations, &rvec, &tvec,
                          Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  result.iterations = solve.iterations;
  result.initial_cost = solve.initial_cost;
  result.final_cost = solve.final_cost;
  if (!rvec.allFinite() || !tvec.allFinite()) {
    result.status = "the optimisation diverged";
    return result;
  }
  result.correction = CorrectionFrom(rvec, tvec, pivot);
  std::vector<camera::Camera> refined = rig;
  for (size_t i = 0; i < rig.size(); ++i) {
    refined[i].cam_from_world = rig[i].cam_from_world * result.correction;
    result.moved_m =
        std::max(result.moved_m, (refined[i].CentreInWorld() - rig[i].CentreInWorld()).norm());
  }
  result.rotated_deg = rvec.norm() * 180.0 / M_PI;
  result.status = LineRefinementRefusal(result.moved_m, options.max_move_m, result.initial_cost,
                                        result.final_cost, /*rig=*/true);
  // As for one camera (lines.cc): no move that raises the line error, over all the cameras'
  // line pixels (each at most the gate; those off the field count the gate).
  std::vector<LineErrorStats> after = result.before;
  double sum_before = 0.0, sum_after = 0.0;
  for (size_t i = 0; i < rig.size(); ++i) {
    if (pixels[i].empty()) continue;
    after[i] = LineError(refined[i], pixels[i], field, options.gate_m);
    const auto n = static_cast<double>(pixels[i].size());
    sum_before += result.before[i].truncated_mean_mm * n;
    sum_after += after[i].truncated_mean_mm * n;
  }
  if (result.status.empty() && sum_after > sum_before) {
    result.status = "the line error would rise (summed over the cameras' line pixels)";
  }
  if (result.status.empty()) {
    result.accepted = true;
    result.cameras = refined;
    result.after = after;
  }
  return result;
}

RigRefineResult RefineRigWithLines(const std::vector<camera::Camera>& rig,
                                   const std::vector<cv::Mat>& images,
                                   const field::FieldModel& field, const RefineOptions& options) {
  options.Check();
  FV_REQUIRE(images.size() == rig.size(), "{} cameras but {} frames", rig.size(), images.size());
  std::vector<std::vector<Eigen::Vector2d>> pixels(rig.size());
  for (size_t i = 0; i < rig.size(); ++i) {
    if (images[i].empty()) continue;
    CheckImageSize(images[i], rig[i], "frame of " + rig[i].name, rig[i].name);
    pixels[i] = DetectLinePixels(images[i], rig[i], field, options.detect);
  }
  return RefineRigWithLinePixels(rig, pixels, field, options);
}

}  // namespace fv::calib
