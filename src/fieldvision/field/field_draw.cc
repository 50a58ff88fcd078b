#include "fieldvision/field/field_draw.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"

namespace fv::field {
namespace {

constexpr int kShift = 4;  // sub-pixel bits for cv drawing
cv::Point Fixed(const cv::Point2d& p) {
  return {static_cast<int>(std::lround(p.x * (1 << kShift))),
          static_cast<int>(std::lround(p.y * (1 << kShift)))};
}

}  // namespace

TopView TopView::ForField(const FieldModel& field, int width_px, double extra_margin_m) {
  FV_REQUIRE(width_px > 10, "top view width must be > 10 px (got {})", width_px);
  TopView v;
  const double hx = field.HalfLengthWithSurround() + extra_margin_m;
  const double hy = field.HalfWidthWithSurround() + extra_margin_m;
  v.px_per_m = width_px / (2 * hx);
  v.x_min_m = -hx;
  v.y_max_m = hy;
  const double height_px = 2 * hy * v.px_per_m;
  FV_REQUIRE(height_px >= 1 && width_px * height_px <= 300e6,
             "a top view of field '{}' {} px wide would be {:.0f} px high (at most 300 Mpx in all)",
             field.name, width_px, height_px);
  v.size = cv::Size(width_px, static_cast<int>(std::lround(height_px)));
  return v;
}

void DrawFieldLines(cv::Mat& image, const FieldModel& field, const TopView& view,
                    const cv::Scalar& colour, int thickness_px) {
  auto thick = [&](double w) {
    return thickness_px > 0 ? thickness_px
                            : std::max(1, static_cast<int>(std::lround(w * view.px_per_m)));
  };
  for (const auto& s : field.segments) {
    cv::line(image, Fixed(view.ToPixel(s.a)), Fixed(view.ToPixel(s.b)), colour, thick(s.width_m),
             cv::LINE_AA, kShift);
  }
  for (const auto& a : field.arcs) {
    const int n =
        std::max(8, static_cast<int>((a.end_rad - a.start_rad) * a.radius_m * view.px_per_m / 2));
    std::vector<cv::Point> pts;
    for (int i = 0; i <= n; ++i) {
      const double t = a.start_rad + (a.end_rad - a.start_rad) * i / n;
      pts.push_back(
          Fixed(view.ToPixel(a.centre + a.radius_m * Eigen::Vector2d(std::cos(t), std::sin(t)))));
    }
    cv::polylines(image, pts, false, colour, thick(a.width_m), cv::LINE_AA, kShift);
  }
  for (const auto& g : field.goals) {
    const double x_back = g.line_x_m + g.side * g.depth_m;
    std::vector<cv::Point> pts = {
        Fixed(view.ToPixel({g.line_x_m, g.y_min_m})), Fixed(view.ToPixel({x_back, g.y_min_m})),
        Fixed(view.ToPixel({x_back, g.y_max_m})), Fixed(view.ToPixel({g.line_x_m, g.y_max_m}))};
    cv::polylines(image, pts, false, colour, std::max(1, thick(g.post_width_m) / 2), cv::LINE_AA,
                  kShift);
  }
  for (const auto& h : field.hoops) {
    cv::circle(image, Fixed(view.ToPixel(h.centre_m.head<2>())),
               static_cast<int>(std::lround(h.radius_m * view.px_per_m * (1 << kShift))),
               cv::Scalar(0, 110, 255), std::max(1, thick(0.02)), cv::LINE_AA, kShift);
  }
}

cv::Mat DrawField(const FieldModel& field, const TopView& view, const FieldDrawOptions& options) {
  cv::Mat image(view.size, CV_8UC3, options.background * 0.8);
  if (options.surround) {
    const cv::Point2d a = view.ToPixel({-field.length_m / 2, field.width_m / 2});
    const cv::Point2d b = view.ToPixel({field.length_m / 2, -field.width_m / 2});
    cv::rectangle(image, cv::Rect(cv::Point(a), cv::Point(b)), options.background, cv::FILLED);
  }
  DrawFieldLines(image, field, view, options.line_colour);
  if (options.keypoints) {
    for (const auto& k : field.keypoints) {
      const cv::Point2d p = view.ToPixel(k.position_m.head<2>());
      const cv::Scalar c = k.position_m.z() > 0 ? cv::Scalar(0, 200, 255) : cv::Scalar(0, 0, 255);
      cv::circle(image, p, 3, c, cv::FILLED, cv::LINE_AA);
      if (options.keypoint_names) {
        cv::putText(image, k.name, p + cv::Point2d(4, -3), cv::FONT_HERSHEY_SIMPLEX, 0.3,
                    cv::Scalar(20, 20, 20), 1, cv::LINE_AA);
      }
    }
  }
  return image;
}

}  // namespace fv::field
