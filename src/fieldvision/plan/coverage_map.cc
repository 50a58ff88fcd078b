#include "fieldvision/plan/coverage_map.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/field/field_draw.h"
#include "fieldvision/util/error.h"

namespace fv::plan {
namespace {

const cv::Vec3b kNoData(70, 70, 70);

cv::Vec3b CountColour(int k) {
  static const std::vector<cv::Vec3b> kPalette = {
      {70, 70, 70},  {50, 50, 220}, {0, 150, 255}, {0, 230, 230},  {80, 220, 80},
      {40, 150, 40}, {200, 200, 0}, {220, 120, 0}, {200, 60, 120}, {150, 40, 150}};
  return kPalette[std::min<size_t>(k, kPalette.size() - 1)];
}

cv::Vec3b TurboColour(double t) {
  static const cv::Mat kLut = [] {
    cv::Mat grey(1, 256, CV_8U);
    for (int i = 0; i < 256; ++i) grey.at<uchar>(0, i) = static_cast<uchar>(i);
    cv::Mat colour;
    cv::applyColorMap(grey, colour, cv::COLORMAP_TURBO);
    return colour;
  }();
  const int i = std::clamp(static_cast<int>(std::lround(t * 255)), 0, 255);
  return kLut.at<cv::Vec3b>(0, i);
}

const std::vector<cv::Scalar> kCameraColours = {{255, 255, 255}, {255, 0, 255}, {255, 255, 0},
                                                {0, 255, 255},   {255, 128, 0}, {128, 0, 255},
                                                {0, 128, 255},   {128, 255, 0}};

void Text(cv::Mat& img, const std::string& s, cv::Point at, double scale,
          const cv::Scalar& colour) {
  cv::putText(img, s, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(img, s, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

// The image border of `cam` cast onto the plane z = height, as polylines (broken where the
// border is above the horizon or very far away).
std::vector<std::vector<cv::Point>> Footprint(const camera::Camera& cam, double height,
                                              const field::TopView& view, double max_range_m) {
  std::vector<Eigen::Vector2d> border;
  const int steps = 60;
  border.reserve(4 * steps + 1);
  const double w = cam.width - 0.5, h = cam.height - 0.5;
  for (int s = 0; s < steps; ++s) border.emplace_back(-0.5 + (w + 0.5) * s / steps, -0.5);
  for (int s = 0; s < steps; ++s) border.emplace_back(w, -0.5 + (h + 0.5) * s / steps);
  for (int s = 0; s < steps; ++s) border.emplace_back(w - (w + 0.5) * s / steps, h);
  for (int s = 0; s <= steps; ++s) border.emplace_back(-0.5, h - (h + 0.5) * s / steps);
  std::vector<std::vector<cv::Point>> lines(1);
  const Eigen::Vector3d centre = cam.CentreInWorld();
  for (const auto& uv : border) {
    const auto ray = cam.RayFromPixel(uv);
    std::optional<Eigen::Vector3d> hit;
    if (ray) hit = geometry::IntersectHorizontalPlane(*ray, height);
    if (!hit || (*hit - centre).norm() > max_range_m) {
      if (!lines.back().empty()) lines.emplace_back();
      continue;
    }
    lines.back().push_back(view.ToPixel(hit->head<2>()));
  }
  return lines;
}

}  // namespace

void CoverageMapOptions::Check() const {
  // Six maps of up to 8000 px (with a legend) stay under 2 GB in all.
  FV_REQUIRE(width_px >= 200 && width_px <= 8000, "width_px must be in [200, 8000] (got {})",
             width_px);
  CheckInRange(alpha, 0, 1, "alpha");
  CheckNonNegative(err_scale_m, "err_scale_m");
}

namespace {

// The top view with room for cameras standing outside the drawn area.
field::TopView MapView(const std::vector<camera::Camera>& cameras, const field::FieldModel& field,
                       int width_px) {
  double extra_m = 0.3;
  for (const camera::Camera& c : cameras) {
    const Eigen::Vector3d p = c.CentreInWorld();
    extra_m = std::max(extra_m, std::abs(p.x()) - field.HalfLengthWithSurround() + 0.8);
    extra_m = std::max(extra_m, std::abs(p.y()) - field.HalfWidthWithSurround() + 0.8);
  }
  return field::TopView::ForField(field, width_px, extra_m);
}

// The layer's cells in their colours, blended over the field with `alpha`.
void PaintCells(cv::Mat& img, const CoverageLayer& layer, CoverageMapKind kind,
                const field::TopView& view, double err_scale, double alpha) {
  cv::Mat overlay = img.clone();
  auto colour_of = [&](size_t cell) -> cv::Vec3b {
    switch (kind) {
      case CoverageMapKind::kCount:
        return CountColour(layer.count[cell]);
      case CoverageMapKind::kAngle: {
        const double a = layer.best_angle_deg[cell];
        return std::isnan(a) ? kNoData : TurboColour(a / 180.0);
      }
      case CoverageMapKind::kError: {
        const double e = layer.err_rms_m[cell];
        return std::isnan(e) ? kNoData : TurboColour(e / err_scale);
      }
    }
    return kNoData;
  };
  for (int j = 0; j < layer.ny; ++j) {
    for (int i = 0; i < layer.nx; ++i) {
      const Eigen::Vector3d c = layer.CellCentre(i, j);
      const cv::Point2d a =
          view.ToPixel({c.x() - 0.5 * layer.step_x_m, c.y() + 0.5 * layer.step_y_m});
      const cv::Point2d b =
          view.ToPixel({c.x() + 0.5 * layer.step_x_m, c.y() - 0.5 * layer.step_y_m});
      const cv::Vec3b col = colour_of(static_cast<size_t>(j) * layer.nx + i);
      cv::rectangle(overlay, cv::Point(std::lround(a.x), std::lround(a.y)),
                    cv::Point(std::lround(b.x), std::lround(b.y)),
                    cv::Scalar(col[0], col[1], col[2]), cv::FILLED);
    }
  }
  cv::addWeighted(overlay, alpha, img, 1 - alpha, 0, img);
}

// Each camera's footprint, position, aim and label.
void DrawCameras(cv::Mat& img, const std::vector<camera::Camera>& cameras, double height_m,
                 const field::TopView& view, double range_m, double scale, bool footprints) {
  for (size_t k = 0; k < cameras.size(); ++k) {
    const camera::Camera& cam = cameras[k];
    const cv::Scalar& colour = kCameraColours[k % kCameraColours.size()];
    if (footprints) {
      for (const auto& line : Footprint(cam, height_m, view, range_m)) {
        if (line.size() > 1) cv::polylines(img, line, false, colour, 1, cv::LINE_AA);
      }
    }
    const Eigen::Vector3d eye = cam.CentreInWorld();
    const cv::Point2d p = view.ToPixel(eye.head<2>());
    const Eigen::Vector3d axis = cam.AxisInWorld();
    Eigen::Vector3d aim = eye + 5.0 * axis;
    if (axis.z() < -1e-6) aim = eye + std::min(range_m, (height_m - eye.z()) / axis.z()) * axis;
    cv::arrowedLine(img, p, view.ToPixel(aim.head<2>()), colour, std::max(1, int(2 * scale)),
                    cv::LINE_AA, 0, 0.03);
    cv::circle(img, p, std::max(4, int(9 * scale)), cv::Scalar(0, 0, 0), cv::FILLED, cv::LINE_AA);
    cv::circle(img, p, std::max(3, int(7 * scale)), colour, cv::FILLED, cv::LINE_AA);
    // The label on the side of the marker that faces the image centre, so it stays inside.
    const std::string label = fmt::format("{} ({:.1f} m)", cam.name, eye.z());
    int baseline = 0;
    const cv::Size text =
        cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, 0.5 * scale, 1, &baseline);
    const int tx =
        p.x < 0.5 * img.cols ? int(p.x + 10 * scale) : int(p.x - 10 * scale) - text.width;
    const int ty = p.y < 0.5 * img.rows ? int(p.y + 8 * scale) + text.height : int(p.y - 8 * scale);
    Text(img, label, cv::Point(tx, ty), 0.5 * scale, colour);
  }
}

// The legend strip below the map: count boxes, or the colour scale with ticks.
cv::Mat Legend(const CoverageLayer& layer, CoverageMapKind kind, const CoverageOptions& coverage,
               double err_scale, int cols, double scale) {
  const int strip_h = std::max(50, int(70 * scale));
  cv::Mat legend(strip_h, cols, CV_8UC3, cv::Scalar(30, 30, 30));
  const int pad = int(15 * scale);
  const double ts = 0.5 * scale;
  std::string title;
  if (kind == CoverageMapKind::kCount) {
    title = fmt::format("cameras seeing the ball, z = {:.2f} m", layer.height_m);
    const int n = static_cast<int>(layer.fraction_exactly.size());
    const int box = int(60 * scale);
    for (int k = 0; k < n; ++k) {
      const cv::Vec3b c = CountColour(k);
      const int x = pad + k * (box + pad) + int(cols * 0.45);
      cv::rectangle(legend, cv::Rect(x, pad, box, strip_h - 2 * pad), cv::Scalar(c[0], c[1], c[2]),
                    cv::FILLED);
      Text(legend, fmt::format("{}: {:.0f}%", k, 100 * layer.fraction_exactly[k]),
           cv::Point(x + 3, strip_h / 2 + 5), 0.4 * scale, cv::Scalar(255, 255, 255));
    }
  } else {
    const bool angle = kind == CoverageMapKind::kAngle;
    title = angle ? fmt::format("best pair angle (deg), good {:.0f}-{:.0f}, z = {:.2f} m",
                                coverage.good_angle_min_deg, coverage.good_angle_max_deg,
                                layer.height_m)
                  : fmt::format("expected 3D error (mm, {:.2f} px noise), z = {:.2f} m",
                                coverage.pixel_noise_px, layer.height_m);
    const int x0 = int(cols * 0.45), x1 = cols - 3 * pad;
    for (int x = x0; x < x1; ++x) {
      const cv::Vec3b c = TurboColour(double(x - x0) / (x1 - x0));
      cv::line(legend, cv::Point(x, pad), cv::Point(x, strip_h / 2), cv::Scalar(c[0], c[1], c[2]));
    }
    const double top = angle ? 180.0 : 1000 * err_scale;
    std::vector<double> ticks;
    if (angle) {
      ticks = {0, coverage.good_angle_min_deg, 90, coverage.good_angle_max_deg, 180};
    } else {
      for (int t = 0; t <= 4; ++t) ticks.push_back(top * t / 4);
    }
    for (double t : ticks) {
      const int x = x0 + int((x1 - x0) * t / top);
      cv::line(legend, cv::Point(x, pad), cv::Point(x, strip_h / 2 + 4), cv::Scalar(255, 255, 255));
      Text(legend, fmt::format("{:.0f}", t), cv::Point(x - 8, strip_h - pad / 2), 0.4 * scale,
           cv::Scalar(255, 255, 255));
    }
    Text(legend, "grey: < 2 cameras", cv::Point(x1 - int(140 * scale), pad - 2), 0.35 * scale,
         cv::Scalar(200, 200, 200));
  }
  Text(legend, title, cv::Point(pad, strip_h / 2 + 5), ts, cv::Scalar(255, 255, 255));
  return legend;
}

}  // namespace

cv::Mat DrawCoverageMap(const CoverageLayer& layer, CoverageMapKind kind,
                        const std::vector<camera::Camera>& cameras, const field::FieldModel& field,
                        const CoverageOptions& coverage, const CoverageMapOptions& options) {
  options.Check();
  const field::TopView view =
      MapView(cameras, field, options.width_px - field::kTopViewFrameWidthPx);
  cv::Mat img = field::DrawField(field, view);
  double err_scale = options.err_scale_m;
  if (err_scale <= 0) err_scale = std::isfinite(layer.err_max_m) ? layer.err_max_m : 0.1;
  PaintCells(img, layer, kind, view, err_scale, options.alpha);
  field::DrawFieldLines(img, field, view, cv::Scalar(255, 255, 255));
  const double range_m =
      3 * std::hypot(field.HalfLengthWithSurround(), field.HalfWidthWithSurround());
  const double scale = options.width_px / 1400.0;
  DrawCameras(img, cameras, layer.height_m, view, range_m, scale, options.footprints);
  img = field::FrameTopView(img, view, "");
  cv::Mat out;
  cv::vconcat(img, Legend(layer, kind, coverage, err_scale, img.cols, scale), out);
  return out;
}

}  // namespace fv::plan
