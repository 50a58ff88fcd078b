#include "fieldvision/calib/lines.h"

#include <algorithm>
#include <cmath>

#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>
#include <ceres/rotation.h>
#include <fmt/format.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace fv::calib {
namespace {

// Whether a ground point is on the field plus a margin.
bool OnField(const field::FieldModel& field, const Eigen::Vector3d& p, double margin_m) {
  return std::abs(p.x()) <= 0.5 * field.length_m + field.surround_m + margin_m &&
         std::abs(p.y()) <= 0.5 * field.width_m + field.surround_m + margin_m;
}

std::optional<Eigen::Vector3d> GroundPoint(const camera::Camera& camera,
                                           const Eigen::Vector2d& uv) {
  const auto ray = camera.RayFromPixel(uv);
  if (!ray) return std::nullopt;
  return geometry::IntersectHorizontalPlane(*ray, 0.0);
}

// Mask of pixels whose ground point is on the field (plus margin), from a coarse grid of rays.
cv::Mat FieldMask(const camera::Camera& camera, const field::FieldModel& field, double margin_m) {
  constexpr int kStep = 4;
  const int gw = (camera.width + kStep - 1) / kStep + 1;
  const int gh = (camera.height + kStep - 1) / kStep + 1;
  cv::Mat coarse(gh, gw, CV_8U, cv::Scalar(0));
  cv::parallel_for_(cv::Range(0, gh), [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      for (int c = 0; c < gw; ++c) {
        const auto g = GroundPoint(camera, Eigen::Vector2d(c * kStep, r * kStep));
        coarse.at<uint8_t>(r, c) = g && OnField(field, *g, margin_m) ? 255 : 0;
      }
    }
  });
  cv::Mat mask;
  cv::resize(coarse, mask, cv::Size(gw * kStep, gh * kStep), 0, 0, cv::INTER_NEAREST);
  return mask(cv::Rect(0, 0, camera.width, camera.height)).clone();
}

// Image areas of the goals (convex hulls of their projected boxes), to be ignored.
cv::Mat GoalMask(const camera::Camera& camera, const field::FieldModel& field) {
  cv::Mat mask(camera.height, camera.width, CV_8U, cv::Scalar(0));
  for (const auto& g : field.goals) {
    const double x0 = g.line_x_m - g.side * g.post_width_m;
    const double x1 = g.line_x_m + g.side * (g.depth_m + g.post_width_m);
    std::vector<cv::Point> corners;
    bool all_in_front = true;
    for (double x : {x0, x1}) {
      for (double y : {g.y_min_m - 2 * g.post_width_m, g.y_max_m + 2 * g.post_width_m}) {
        for (double z : {0.0, g.height_m + 2 * g.post_width_m}) {
          const auto uv = camera.Project(Eigen::Vector3d(x, y, z));
          if (!uv) {
            all_in_front = false;
            continue;
          }
          corners.emplace_back(static_cast<int>(std::lround(uv->x())),
                               static_cast<int>(std::lround(uv->y())));
        }
      }
    }
    if (!all_in_front || corners.empty()) continue;
    std::vector<cv::Point> hull;
    cv::convexHull(corners, hull);
    cv::fillConvexPoly(mask, hull, cv::Scalar(255));
  }
  return mask;
}

int AutoMaxWidthPx(const camera::Camera& camera, const field::FieldModel& field) {
  double widest = 2.0;
  for (const auto& p : field.SampleLines(0.25)) {
    const Eigen::Vector3d pw(p.x(), p.y(), 0.0);
    const auto uv = camera.Project(pw);
    if (!uv || !camera.InImage(*uv)) continue;
    const double depth = (camera.cam_from_world * pw).z();
    widest = std::max(widest, field.line_width_m * std::sqrt(camera.fx * camera.fy) / depth);
  }
  return std::clamp(static_cast<int>(std::ceil(2.5 * widest + 3)), 5, 101);
}

// Intensity-weighted centres of the runs of `mask` along rows (or columns) no longer than
// max_len.
void RunCentres(const cv::Mat& mask, const cv::Mat& weight, int max_len, bool rows,
                std::vector<Eigen::Vector2d>* out) {
  const int outer = rows ? mask.rows : mask.cols;
  const int inner = rows ? mask.cols : mask.rows;
  for (int o = 0; o < outer; ++o) {
    int start = -1;
    for (int i = 0; i <= inner; ++i) {
      const bool on = i < inner && (rows ? mask.at<uint8_t>(o, i) : mask.at<uint8_t>(i, o));
      if (on && start < 0) start = i;
      if (!on && start >= 0) {
        const int len = i - start;
        if (len <= max_len && len >= 1) {
          double sw = 0, s = 0;
          for (int j = start; j < i; ++j) {
            const double w = rows ? weight.at<float>(o, j) : weight.at<float>(j, o);
            sw += w;
            s += w * j;
          }
          const double centre = sw > 0 ? s / sw : 0.5 * (start + i - 1);
          out->push_back(rows ? Eigen::Vector2d(centre, o) : Eigen::Vector2d(o, centre));
        }
        start = -1;
      }
    }
  }
}

// Ground distance to the lines of one line pixel's ray (intrinsics fixed, pose free).
struct LinePixelCost {
  LinePixelCost(const Eigen::Vector2d& ray_xy, const LineDistanceMap* map,
                const ceres::BiCubicInterpolator<ceres::Grid2D<float, 1>>* interp)
      : ray_(ray_xy), map_(map), interp_(interp) {}

  template <typename T>
  bool operator()(const T* rvec, const T* tvec, T* residual) const {
    const T minus_r[3] = {-rvec[0], -rvec[1], -rvec[2]};
    T c_world[3];
    ceres::AngleAxisRotatePoint(minus_r, tvec, c_world);
    for (T& v : c_world) v = -v;
    return Residual(rvec, c_world, residual);
  }

  // The same for a camera centre `c_world` in the world.
  template <typename T>
  bool Residual(const T* rvec, const T* c_world, T* residual) const {
    const T minus_r[3] = {-rvec[0], -rvec[1], -rvec[2]};
    const T d_cam[3] = {T(ray_.x()), T(ray_.y()), T(1.0)};
    T d_world[3];
    ceres::AngleAxisRotatePoint(minus_r, d_cam, d_world);
    if (!(d_world[2] < T(-1e-9)) || !(c_world[2] > T(0))) {
      residual[0] = T(map_->max_distance_m());
      return true;
    }
    const T s = -c_world[2] / d_world[2];
    const T x = c_world[0] + s * d_world[0];
    const T y = c_world[1] + s * d_world[1];
    T row, col;
    map_->ToGrid(x, y, &row, &col);
    interp_->Evaluate(row, col, residual);
    return true;
  }

  Eigen::Vector2d ray_;
  const LineDistanceMap* map_;
  const ceres::BiCubicInterpolator<ceres::Grid2D<float, 1>>* interp_;
};

// The same with the camera's centre fixed (RefineOptions::fix_centre): the rotation free.
struct LinePixelTurnCost {
  template <typename T>
  bool operator()(const T* rvec, T* residual) const {
    const T c_world[3] = {T(centre.x()), T(centre.y()), T(centre.z())};
    return cost.Residual(rvec, c_world, residual);
  }
  LinePixelCost cost;
  Eigen::Vector3d centre;
};

}  // namespace

void CheckImageSize(const cv::Mat& image, const camera::Camera& camera,
                    const std::string& image_name, const std::string& camera_name) {
  FV_REQUIRE(!image.empty(), "image '{}' is empty or unreadable", image_name);
  FV_REQUIRE(image.cols == camera.width && image.rows == camera.height,
             "image '{}' is {}x{} but camera '{}' is {}x{}", image_name, image.cols, image.rows,
             camera_name, camera.width, camera.height);
}

void LineDetectOptions::Check() const {
  CheckInRange(min_tophat, 1.0, 255.0, "detect.min_tophat");
  CheckInRange(max_saturation, 0.0, 255.0, "detect.max_saturation");
  FV_REQUIRE(max_width_px == 0 || (max_width_px >= 2 && max_width_px <= 201),
             "detect.max_width_px must be 0 (auto) or in [2, 201] (got {})", max_width_px);
  CheckNonNegative(field_margin_m, "detect.field_margin_m");
  FV_REQUIRE(max_pixels >= 100, "detect.max_pixels must be >= 100 (got {})", max_pixels);
}

std::vector<Eigen::Vector2d> DetectLinePixels(const cv::Mat& image_bgr,
                                              const camera::Camera& camera,
                                              const field::FieldModel& field,
                                              const LineDetectOptions& options) {
  options.Check();
  CheckImageSize(image_bgr, camera, "frame", camera.name);
  FV_REQUIRE(camera.has_pose, "camera '{}' has no pose; run `calibrate extrinsics` first",
             camera.name);
  cv::Mat bgr = image_bgr;
  if (bgr.channels() == 1) cv::cvtColor(image_bgr, bgr, cv::COLOR_GRAY2BGR);
  FV_REQUIRE(bgr.type() == CV_8UC3, "frame must be an 8-bit BGR or grey image");
  cv::Mat grey, hsv;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  const int max_width =
      options.max_width_px > 0 ? options.max_width_px : AutoMaxWidthPx(camera, field);
  const int k = max_width + 2 + (max_width % 2 == 0 ? 1 : 0);
  cv::Mat tophat;
  cv::morphologyEx(grey, tophat, cv::MORPH_TOPHAT,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
  cv::Mat sat;
  cv::extractChannel(hsv, sat, 1);
  cv::Mat mask = (tophat > options.min_tophat) & (sat < options.max_saturation);
  mask &= FieldMask(camera, field, options.field_margin_m);
  if (options.mask_goals) mask.setTo(0, GoalMask(camera, field));
  cv::Mat weight;
  tophat.convertTo(weight, CV_32F);
  std::vector<Eigen::Vector2d> pixels;
  RunCentres(mask, weight, max_width, true, &pixels);
  RunCentres(mask, weight, max_width, false, &pixels);
  if (static_cast<int>(pixels.size()) > options.max_pixels) {
    std::vector<Eigen::Vector2d> kept;
    kept.reserve(options.max_pixels);
    const double stride = static_cast<double>(pixels.size()) / options.max_pixels;
    for (int i = 0; i < options.max_pixels; ++i) {
      kept.push_back(pixels[static_cast<size_t>(i * stride)]);
    }
    pixels.swap(kept);
  }
  return pixels;
}

LineDistanceMap::LineDistanceMap(const field::FieldModel& field, double resolution_m,
                                 double max_distance_m, int max_cells)
    : resolution_m_(resolution_m), max_distance_m_(max_distance_m) {
  field.Check();
  CheckPositive(resolution_m, "lut_resolution_m");
  CheckPositive(max_distance_m, "lut_max_distance_m");
  FV_REQUIRE(max_cells >= 1000, "max_cells must be >= 1000 (got {})", max_cells);
  const double half_x = field.HalfLengthWithSurround() + max_distance_m;
  const double half_y = field.HalfWidthWithSurround() + max_distance_m;
  const double area = 4 * half_x * half_y;
  resolution_m_ = std::max(resolution_m_, std::sqrt(area / max_cells));
  x0_m_ = -half_x;
  y0_m_ = -half_y;
  cols_ = static_cast<int>(std::ceil(2 * half_x / resolution_m_)) + 1;
  rows_ = static_cast<int>(std::ceil(2 * half_y / resolution_m_)) + 1;
  values_.assign(static_cast<size_t>(rows_) * cols_, static_cast<float>(max_distance_m));
  // Exact distances, each line updating only the cells within max_distance of its bounding box.
  struct Box {
    int r0, r1, c0, c1;
  };
  auto box = [&](double xmin, double xmax, double ymin, double ymax) {
    Box b;
    b.c0 =
        std::max(0, static_cast<int>(std::floor((xmin - max_distance_m - x0_m_) / resolution_m_)));
    b.c1 = std::min(cols_ - 1,
                    static_cast<int>(std::ceil((xmax + max_distance_m - x0_m_) / resolution_m_)));
    b.r0 =
        std::max(0, static_cast<int>(std::floor((ymin - max_distance_m - y0_m_) / resolution_m_)));
    b.r1 = std::min(rows_ - 1,
                    static_cast<int>(std::ceil((ymax + max_distance_m - y0_m_) / resolution_m_)));
    return b;
  };
  std::vector<std::pair<Box, std::function<double(const Eigen::Vector2d&)>>> items;
  for (const auto& s : field.segments) {
    items.emplace_back(
        box(std::min(s.a.x(), s.b.x()), std::max(s.a.x(), s.b.x()), std::min(s.a.y(), s.b.y()),
            std::max(s.a.y(), s.b.y())),
        [s](const Eigen::Vector2d& p) { return field::DistanceToSegment(p, s.a, s.b); });
  }
  for (const auto& a : field.arcs) {
    items.emplace_back(box(a.centre.x() - a.radius_m, a.centre.x() + a.radius_m,
                           a.centre.y() - a.radius_m, a.centre.y() + a.radius_m),
                       [a](const Eigen::Vector2d& p) { return field::DistanceToArc(p, a); });
  }
  cv::parallel_for_(cv::Range(0, rows_), [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      float* row = values_.data() + static_cast<size_t>(r) * cols_;
      const double y = y0_m_ + r * resolution_m_;
      for (const auto& [b, dist] : items) {
        if (r < b.r0 || r > b.r1) continue;
        for (int c = b.c0; c <= b.c1; ++c) {
          const double d = dist(Eigen::Vector2d(x0_m_ + c * resolution_m_, y));
          if (d < row[c]) row[c] = static_cast<float>(d);
        }
      }
    }
  });
}

double LineDistanceMap::Distance(double x_m, double y_m) const {
  double row, col;
  ToGrid(x_m, y_m, &row, &col);
  if (!(row >= 0 && col >= 0 && row <= rows_ - 1 && col <= cols_ - 1)) return max_distance_m_;
  const int r0 = std::min(static_cast<int>(row), rows_ - 2);
  const int c0 = std::min(static_cast<int>(col), cols_ - 2);
  const double fr = row - r0, fc = col - c0;
  auto at = [&](int r, int c) {
    return static_cast<double>(values_[static_cast<size_t>(r) * cols_ + c]);
  };
  return (1 - fr) * ((1 - fc) * at(r0, c0) + fc * at(r0, c0 + 1)) +
         fr * ((1 - fc) * at(r0 + 1, c0) + fc * at(r0 + 1, c0 + 1));
}

std::string LineErrorStats::Summary() const {
  return fmt::format(
      "line error mean {:.1f} mm, median {:.1f} mm, p95 {:.1f} mm over {} of the {} "
      "line pixels that land on the field (within {:.0f} mm of a line)",
      mean_mm, median_mm, p95_mm, num_inliers, num_pixels, gate_m * 1000);
}

void RequirePaintedLines(const field::FieldModel& field) {
  FV_REQUIRE(field.HasPaintedLines(), "field '{}' has no painted lines to refine the pose against",
             field.name);
}

LineErrorStats LineError(const camera::Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                         const field::FieldModel& field, double gate_m) {
  CheckPositive(gate_m, "gate_m");
  LineErrorStats s;
  s.gate_m = gate_m;
  std::vector<double> mm;
  double truncated_sum_mm = 0.0;
  for (const auto& uv : pixels) {
    const auto g = GroundPoint(camera, uv);
    if (!g || !OnField(field, *g, 0.0)) {
      truncated_sum_mm += 1000.0 * gate_m;
      continue;
    }
    ++s.num_pixels;
    const double d = field.DistanceToLineCentres(g->head<2>());
    truncated_sum_mm += 1000.0 * std::min(d, gate_m);
    if (d <= gate_m) mm.push_back(1000.0 * d);
  }
  if (!pixels.empty()) s.truncated_mean_mm = truncated_sum_mm / static_cast<double>(pixels.size());
  s.num_inliers = static_cast<int>(mm.size());
  if (!mm.empty()) {
    s.mean_mm = util::Mean(mm);
    s.median_mm = util::NearestRankPercentile(mm, 0.5);
    s.p95_mm = util::NearestRankPercentile(mm, 0.95);
  }
  return s;
}

void RefineOptions::Check() const {
  detect.Check();
  CheckInRange(lut_resolution_m, 0.001, 0.5, "lut_resolution_m");
  CheckPositive(lut_max_distance_m, "lut_max_distance_m");
  FV_REQUIRE(!loss_scales_m.empty(), "loss_scales_m must not be empty");
  for (double s : loss_scales_m) CheckPositive(s, "loss_scales_m");
  FV_REQUIRE(max_iterations >= 1, "max_iterations must be >= 1 (got {})", max_iterations);
  CheckPositive(gate_m, "gate_m");
  CheckPositive(max_move_m, "max_move_m");
}

std::string RefineResult::Summary() const {
  return fmt::format(
      "{}: {} line pixels; before: {}; after: {}; camera moved {:.1f} mm, turned {:.3f} deg; {} "
      "iterations",
      accepted ? "refined" : "not refined (" + status + ")", num_line_pixels, before.Summary(),
      after.Summary(), moved_m * 1000, rotated_deg, iterations);
}

std::string LineRefinementRefusal(double moved_m, double max_move_m, double initial_cost,
                                  double final_cost, bool rig) {
  if (moved_m > max_move_m) {
    return fmt::format(
        "{} would move {:.2f} m (> {:.2f} m): {} start pose is too far off or the lines are "
        "ambiguous",
        rig ? "a camera" : "the camera", moved_m, max_move_m, rig ? "the rig's" : "the");
  }
  if (!(final_cost <= initial_cost)) return "no improvement";
  return "";
}

LossScaleSolve SolveOverLossScales(const std::function<void(ceres::Problem&, double)>& build,
                                   const std::vector<double>& scales, int max_iterations,
                                   Eigen::Vector3d* rvec, Eigen::Vector3d* tvec,
                                   const Eigen::Vector3d& rvec_start,
                                   const Eigen::Vector3d& tvec_start) {
  LossScaleSolve out;
  for (double scale : scales) {
    ceres::Problem problem;
    build(problem, scale);
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    so.max_num_iterations = max_iterations;
    so.num_threads = 2;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    out.iterations += static_cast<int>(summary.iterations.size());
  }
  ceres::Problem problem;
  build(problem, scales.back());
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &out.final_cost, nullptr, nullptr, nullptr);
  const Eigen::Vector3d r1 = *rvec, t1 = *tvec;
  *rvec = rvec_start;
  *tvec = tvec_start;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &out.initial_cost, nullptr, nullptr, nullptr);
  *rvec = r1;
  *tvec = t1;
  return out;
}

RefineResult RefineWithLinePixels(const camera::Camera& camera,
                                  const std::vector<Eigen::Vector2d>& pixels,
                                  const field::FieldModel& field, const RefineOptions& options) {
  options.Check();
  RequirePaintedLines(field);
  return RefineWithLinePixels(
      camera, pixels, field,
      LineDistanceMap(field, options.lut_resolution_m, options.lut_max_distance_m), options);
}

RefineResult RefineWithLinePixels(const camera::Camera& camera,
                                  const std::vector<Eigen::Vector2d>& pixels,
                                  const field::FieldModel& field, const LineDistanceMap& map,
                                  const RefineOptions& options) {
  options.Check();
  camera.Check("camera");
  FV_REQUIRE(camera.has_pose, "camera '{}' has no pose; run `calibrate extrinsics` first",
             camera.name);
  RequirePaintedLines(field);
  RefineResult result;
  result.camera = camera;
  result.num_line_pixels = static_cast<int>(pixels.size());
  result.before = LineError(camera, pixels, field, options.gate_m);
  result.after = result.before;
  // Undistorted rays of the pixels (intrinsics are fixed).
  std::vector<Eigen::Vector2d> rays;
  for (const auto& uv : pixels) {
    if (const auto xn = camera.Undistort(uv)) rays.push_back(*xn);
  }
  if (rays.size() < 50) {
    result.status = fmt::format("only {} line pixels; need 50", rays.size());
    return result;
  }
  const ceres::Grid2D<float, 1> grid(map.values().data(), 0, map.rows(), 0, map.cols());
  const ceres::BiCubicInterpolator<ceres::Grid2D<float, 1>> interp(grid);

  Eigen::Vector3d rvec = camera.cam_from_world.Rvec();
  Eigen::Vector3d tvec = camera.cam_from_world.translation;
  const Eigen::Vector3d rvec0 = rvec, tvec0 = tvec;
  const Eigen::Vector3d centre = camera.CentreInWorld();
  auto build = [&](ceres::Problem& problem, double scale) {
    for (const auto& r : rays) {
      if (options.fix_centre) {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<LinePixelTurnCost, 1, 3>(
                new LinePixelTurnCost{LinePixelCost(r, &map, &interp), centre}),
            new ceres::CauchyLoss(scale), rvec.data());
      } else {
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<LinePixelCost, 1, 3, 3>(
                                     new LinePixelCost(r, &map, &interp)),
                                 new ceres::CauchyLoss(scale), rvec.data(), tvec.data());
      }
    }
  };
  const LossScaleSolve solve = SolveOverLossScales(
      build, options.loss_scales_m, options.max_iterations, &rvec, &tvec, rvec0, tvec0);
  if (options.fix_centre) tvec = -geometry::RotationFromRvec(rvec) * centre;
  result.iterations = solve.iterations;
  result.initial_cost = solve.initial_cost;
  result.final_cost = solve.final_cost;
  camera::Camera refined = camera;
  refined.cam_from_world = geometry::Rigid3d::FromRvecTvec(rvec, tvec);
  result.moved_m = (refined.CentreInWorld() - camera.CentreInWorld()).norm();
  result.rotated_deg = geometry::RotationAngleBetween(refined.cam_from_world.rotation,
                                                      camera.cam_from_world.rotation) *
                       180.0 / M_PI;
  if (!rvec.allFinite() || !tvec.allFinite()) {
    result.status = "the optimisation diverged";
    return result;
  }
  result.status = LineRefinementRefusal(result.moved_m, options.max_move_m, result.initial_cost,
                                        result.final_cost, /*rig=*/false);
  const LineErrorStats after = LineError(refined, pixels, field, options.gate_m);
  // The robust cost can fall while the line error the user sees rises (an exact pose moved by
  // the lines' own noise): such a pose is no refinement.
  if (result.status.empty() && after.truncated_mean_mm > result.before.truncated_mean_mm) {
    result.status = fmt::format(
        "the line error would rise (mean {:.1f} -> {:.1f} mm, {} -> {} line pixels within {:.0f} "
        "mm of a line)",
        result.before.mean_mm, after.mean_mm, result.before.num_inliers, after.num_inliers,
        1000.0 * options.gate_m);
  }
  if (result.status.empty()) {
    result.accepted = true;
    result.camera = refined;
    result.after = after;
  }
  return result;
}

RefineResult RefineWithLines(const camera::Camera& camera, const cv::Mat& image_bgr,
                             const field::FieldModel& field, const RefineOptions& options) {
  options.Check();
  CheckImageSize(image_bgr, camera, "frame", camera.name);
  const auto pixels = DetectLinePixels(image_bgr, camera, field, options.detect);
  return RefineWithLinePixels(camera, pixels, field, options);
}

}  // namespace fv::calib
