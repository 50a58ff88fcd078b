#include "fieldvision/calib/check.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"

namespace fv::calib {
namespace {

void DrawPolyline3d(cv::Mat& image, const camera::Camera& camera,
                    const std::vector<Eigen::Vector3d>& pts, const cv::Scalar& colour,
                    int thickness) {
  std::optional<Eigen::Vector2d> prev;
  const double big = 4.0 * std::max(camera.width, camera.height);
  for (const auto& p : pts) {
    std::optional<Eigen::Vector2d> uv = camera.Project(p);
    // Far outside the image the distortion polynomial folds back; do not draw there.
    if (uv && !camera.InImage(*uv, -0.5 * big)) uv.reset();
    if (uv && prev) {
      cv::line(image, cv::Point2d(prev->x(), prev->y()), cv::Point2d(uv->x(), uv->y()), colour,
               thickness, cv::LINE_AA);
    }
    prev = uv;
  }
}

}  // namespace

void CheckOptions::Check() const {
  detect.Check();
  CheckPositive(gate_m, "gate_m");
  FV_REQUIRE(thickness_px >= 1 && thickness_px <= 20, "thickness_px must be in [1, 20] (got {})",
             thickness_px);
  CheckInRange(sample_step_m, 0.001, 5.0, "sample_step_m");
}

std::string CheckResult::Summary() const {
  std::string s = lines.Summary();
  if (!points.empty()) {
    double sum_px = 0, sum_mm = 0;
    int n_mm = 0;
    for (const auto& p : points) {
      sum_px += p.err_px;
      if (p.err_mm) {
        sum_mm += *p.err_mm;
        ++n_mm;
      }
    }
    s += fmt::format("; {} known points: mean {:.2f} px, {:.0f} mm", points.size(),
                     sum_px / points.size(), n_mm ? sum_mm / n_mm : 0.0);
  }
  return s;
}

void DrawFieldOverlay(cv::Mat& image, const camera::Camera& camera, const field::FieldModel& field,
                      const cv::Scalar& colour, int thickness_px, double step_m) {
  for (const auto& s : field.segments) {
    const int n = std::max(1, static_cast<int>(std::ceil((s.b - s.a).norm() / step_m)));
    std::vector<Eigen::Vector3d> pts;
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector2d p = s.a + (s.b - s.a) * (static_cast<double>(i) / n);
      pts.emplace_back(p.x(), p.y(), 0.0);
    }
    DrawPolyline3d(image, camera, pts, colour, thickness_px);
  }
  for (const auto& a : field.arcs) {
    const double len = a.radius_m * (a.end_rad - a.start_rad);
    const int n = std::max(2, static_cast<int>(std::ceil(len / step_m)));
    std::vector<Eigen::Vector3d> pts;
    for (int i = 0; i <= n; ++i) {
      const double t = a.start_rad + (a.end_rad - a.start_rad) * i / n;
      pts.emplace_back(a.centre.x() + a.radius_m * std::cos(t),
                       a.centre.y() + a.radius_m * std::sin(t), 0.0);
    }
    DrawPolyline3d(image, camera, pts, colour, thickness_px);
  }
  for (const auto& g : field.goals) {
    for (double y : {g.y_min_m, g.y_max_m}) {
      DrawPolyline3d(
          image, camera,
          {Eigen::Vector3d(g.line_x_m, y, 0), Eigen::Vector3d(g.line_x_m, y, g.height_m)}, colour,
          thickness_px);
    }
    DrawPolyline3d(image, camera,
                   {Eigen::Vector3d(g.line_x_m, g.y_min_m, g.height_m),
                    Eigen::Vector3d(g.line_x_m, g.y_max_m, g.height_m)},
                   colour, thickness_px);
  }
  for (const auto& k : field.keypoints) {
    const auto uv = camera.Project(k.position_m);
    if (uv && camera.InImage(*uv)) {
      cv::circle(image, cv::Point2d(uv->x(), uv->y()), 3 + thickness_px, colour, 1, cv::LINE_AA);
    }
  }
}

namespace {

// Title (the line error, over how many line pixels; the clicked points' error) and a legend of
// the overlay's colours, on dark boxes in the top- and bottom-left corners.
void DrawCheckLegend(CheckResult& result, const CheckOptions& options, const cv::Scalar& clicked) {
  cv::Mat& img = result.overlay;
  const auto text = [&img](const std::string& s, cv::Point p, double scale, int thick) {
    cv::putText(img, s, p, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), thick + 2,
                cv::LINE_AA);
    cv::putText(img, s, p, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), thick,
                cv::LINE_AA);
  };
  std::string title = fmt::format("line error mean {:.0f} mm, p95 {:.0f} mm ({} of {} line pixels)",
                                  result.lines.mean_mm, result.lines.p95_mm,
                                  result.lines.num_inliers, result.lines.num_pixels);
  if (!result.points.empty()) {
    double ss = 0;
    for (const auto& p : result.points) ss += p.err_px * p.err_px;
    title += fmt::format("; clicked points {:.1f} px rms",
                         std::sqrt(ss / static_cast<double>(result.points.size())));
  }
  // Sizes follow the image (1280 px wide: the title at 0.8, the legend at 0.5).
  const double k = std::clamp(img.cols / 1280.0, 0.7, 1.5);
  int base = 0;
  const int title_w = cv::getTextSize(title, cv::FONT_HERSHEY_SIMPLEX, 0.8 * k, 2, &base).width;
  const double title_scale = 0.8 * k * std::min(1.0, (img.cols - 24.0) / std::max(1, title_w));
  text(title, {12, static_cast<int>(32 * k)}, title_scale, title_scale > 0.5 ? 2 : 1);
  struct Entry {
    cv::Scalar colour;
    std::string label;
  };
  std::vector<Entry> entries = {
      {options.model_colour, "the field's lines projected with this pose"}};
  if (options.draw_line_pixels) {
    entries.push_back({cv::Scalar(0, 255, 0), "line pixel within 5 cm of a line"});
    entries.push_back(
        {cv::Scalar(0, 255, 255), fmt::format("within {:.0f} cm (counted)", 100 * options.gate_m)});
    entries.push_back({cv::Scalar(0, 0, 255), "farther: not counted"});
  }
  if (!result.points.empty()) entries.push_back({clicked, "clicked point -> its projection"});
  const double label_scale = 0.5 * k;
  int label_w = 0;
  for (const auto& e : entries) {
    label_w = std::max(
        label_w, cv::getTextSize(e.label, cv::FONT_HERSHEY_SIMPLEX, label_scale, 1, &base).width);
  }
  const int row_h = static_cast<int>(22 * k), swatch = static_cast<int>(22 * k);
  const int y0 = img.rows - 12 - row_h * static_cast<int>(entries.size());
  cv::rectangle(img,
                cv::Rect(6, y0 - row_h * 3 / 4, swatch + label_w + 30,
                         row_h * static_cast<int>(entries.size()) + row_h / 2),
                cv::Scalar(40, 40, 40), cv::FILLED);
  for (size_t i = 0; i < entries.size(); ++i) {
    const int y = y0 + row_h * static_cast<int>(i);
    cv::rectangle(img, cv::Rect(14, y - row_h / 2, swatch, row_h / 2), entries[i].colour,
                  cv::FILLED);
    text(entries[i].label, {22 + swatch, y}, label_scale, 1);
  }
}

}  // namespace

CheckResult CheckCalibration(const camera::Camera& camera, const cv::Mat& image_bgr,
                             const field::FieldModel& field,
                             const std::vector<PointCorrespondence>& known_points,
                             const CheckOptions& options) {
  options.Check();
  camera.Check("camera");
  FV_REQUIRE(camera.has_pose, "camera '{}' has no pose; run `calibrate extrinsics` first",
             camera.name);
  CheckImageSize(image_bgr, camera, "frame", camera.name);
  CheckResult result;
  if (image_bgr.channels() == 1) {
    cv::cvtColor(image_bgr, result.overlay, cv::COLOR_GRAY2BGR);
  } else {
    result.overlay = image_bgr.clone();
  }
  const auto pixels = DetectLinePixels(result.overlay, camera, field, options.detect);
  result.lines = LineError(camera, pixels, field, options.gate_m);
  DrawFieldOverlay(result.overlay, camera, field, options.model_colour, options.thickness_px,
                   options.sample_step_m);
  if (options.draw_line_pixels) {
    // Green within 5 cm of the model, yellow within the gate, red beyond.
    for (const auto& uv : pixels) {
      const auto ray = camera.RayFromPixel(uv);
      const auto g = ray ? geometry::IntersectHorizontalPlane(*ray, 0.0) : std::nullopt;
      if (!g) continue;
      const double d = field.DistanceToLineCentres(g->head<2>());
      const cv::Scalar c = d < 0.05             ? cv::Scalar(0, 255, 0)
                           : d < options.gate_m ? cv::Scalar(0, 255, 255)
                                                : cv::Scalar(0, 0, 255);
      cv::circle(result.overlay, cv::Point2d(uv.x(), uv.y()), 1, c, -1);
    }
  }
  const cv::Scalar clicked_colour(255, 255, 0);  // cyan: clicked points and their residuals
  if (!known_points.empty()) {
    result.points = PointResiduals(camera, known_points);
    for (const auto& p : result.points) {
      cv::circle(result.overlay, cv::Point2d(p.uv_px.x(), p.uv_px.y()), 6, clicked_colour, 2,
                 cv::LINE_AA);
      if (p.projected_px.allFinite()) {
        cv::line(result.overlay, cv::Point2d(p.uv_px.x(), p.uv_px.y()),
                 cv::Point2d(p.projected_px.x(), p.projected_px.y()), clicked_colour, 1,
                 cv::LINE_AA);
        cv::circle(result.overlay, cv::Point2d(p.projected_px.x(), p.projected_px.y()), 2,
                   clicked_colour, cv::FILLED, cv::LINE_AA);
      }
    }
  }
  DrawCheckLegend(result, options, clicked_colour);
  return result;
}

void WritePointErrorTable(const std::string& path, const std::vector<PointResidual>& points) {
  util::CsvWriter w(
      path,
      {"name", "u", "v", "x_m", "y_m", "z_m", "u_proj", "v_proj", "err_px", "err_mm", "inlier"}, 4);
  for (const auto& p : points) {
    w << p.name << p.uv_px.x() << p.uv_px.y() << p.p_world.x() << p.p_world.y() << p.p_world.z()
      << p.projected_px.x() << p.projected_px.y() << p.err_px
      << (p.err_mm ? *p.err_mm : std::nan("")) << (p.inlier ? 1 : 0);
    w.EndRow();
  }
  w.Close();
}

}  // namespace fv::calib
