#include "fieldvision/field/field_draw.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"

namespace fv::field {
namespace {

constexpr int kShift = 4;  // sub-pixel bits for cv drawing
cv::Point Fixed(const cv::Point2d& p) {
  return {static_cast<int>(std::lround(p.x * (1 << kShift))),
          static_cast<int>(std::lround(p.y * (1 << kShift)))};
}

constexpr double kNameScale = 0.3;

// Where a keypoint's name goes beside its dot at `p`: the first of eight places around it (right
// and left, above and below, then farther) that stays inside the image and clear of the names
// placed so far (added to `placed`); else the first place.
cv::Point NamePlace(const std::string& name, const cv::Point2d& p, const cv::Size& image,
                    std::vector<cv::Rect>* placed) {
  int base = 0;
  const cv::Size t = cv::getTextSize(name, cv::FONT_HERSHEY_SIMPLEX, kNameScale, 1, &base);
  const cv::Rect bounds({0, 0}, image);
  std::optional<cv::Rect> first;
  for (const int dy : {-3, 3 + t.height, -3 - t.height, 3 + 2 * t.height}) {
    for (const int dx : {4, -4 - t.width}) {
      const cv::Rect r(static_cast<int>(p.x) + dx, static_cast<int>(p.y) + dy - t.height, t.width,
                       t.height + base);
      if (!first) first = r;
      const bool clear = std::none_of(placed->begin(), placed->end(),
                                      [&](const cv::Rect& q) { return (q & r).area() > 0; });
      if ((r & bounds) == r && clear) {
        placed->push_back(r);
        return {r.x, r.y + t.height};
      }
    }
  }
  placed->push_back(*first);
  return {first->x, first->y + t.height};
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
    std::vector<cv::Rect> placed;  // names drawn so far
    for (const auto& k : field.keypoints) {
      const cv::Point2d p = view.ToPixel(k.position_m.head<2>());
      const cv::Scalar c = k.position_m.z() > 0 ? cv::Scalar(0, 200, 255) : cv::Scalar(0, 0, 255);
      cv::circle(image, p, 3, c, cv::FILLED, cv::LINE_AA);
      if (options.keypoint_names) {
        const cv::Point at = NamePlace(k.name, p, image.size(), &placed);
        cv::putText(image, k.name, at, cv::FONT_HERSHEY_SIMPLEX, kNameScale, cv::Scalar(20, 20, 20),
                    1, cv::LINE_AA);
      }
    }
  }
  return image;
}

double NiceStep(double range) {
  const double raw = range / 8;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10 * p;
}

double TickValue(double v, double step) {
  const double r = std::round(v / step) * step;
  return r == 0.0 ? 0.0 : r;
}

std::vector<std::string> WrapText(const std::string& text, int width_px, double font_scale) {
  const auto text_width = [font_scale](const std::string& t) {
    int baseline = 0;
    return cv::getTextSize(t, cv::FONT_HERSHEY_SIMPLEX, font_scale, 1, &baseline).width;
  };
  std::vector<std::string> lines;
  std::string line;
  const auto add = [&](const std::string& piece, bool space) {
    const std::string longer = line.empty() ? piece : line + (space ? " " : "") + piece;
    if (!line.empty() && text_width(longer) > width_px) {
      lines.push_back(line);
      line = piece;
    } else {
      line = longer;
    }
  };
  std::istringstream words(text);
  std::string word;
  while (words >> word) {
    if (text_width(word) <= width_px) {
      add(word, true);
      continue;
    }
    bool first = true;
    std::string piece;
    for (size_t c = 0; c < word.size(); ++c) {
      piece += word[c];
      const bool cut = word[c] == '/' || text_width(piece + word.substr(c + 1, 1)) > width_px;
      if (cut || c + 1 == word.size()) {
        add(piece, first);
        first = false;
        piece.clear();
      }
    }
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

cv::Mat FrameTopView(const cv::Mat& image, const TopView& view, const std::string& caption) {
  constexpr double kCaptionScale = 0.42;
  const cv::Scalar white(255, 255, 255), dark(60, 60, 60), black(0, 0, 0);
  auto text = [](cv::Mat& img, const std::string& s, cv::Point p, const cv::Scalar& c,
                 double scale) {
    cv::putText(img, s, p, cv::FONT_HERSHEY_SIMPLEX, scale, c, 1, cv::LINE_AA);
  };
  const int ml = kTopViewFrameLeftPx, mr = kTopViewFrameWidthPx - ml, mt = kTopViewFrameTopPx;
  // The caption in lines that fit the width.
  const std::vector<std::string> lines =
      WrapText(caption, image.cols + ml + mr - 10, kCaptionScale);
  const int line_h = 17, mb = 45 + line_h * static_cast<int>(lines.size());
  cv::Mat out(image.rows + mt + mb, image.cols + ml + mr, CV_8UC3, white);
  image.copyTo(out(cv::Rect(ml, mt, image.cols, image.rows)));
  const Eigen::Vector2d lo = view.ToField({0.0, static_cast<double>(image.rows)});
  const Eigen::Vector2d hi = view.ToField({static_cast<double>(image.cols), 0.0});
  const double step = NiceStep(std::max(hi.x() - lo.x(), hi.y() - lo.y()));
  for (double x = std::ceil(lo.x() / step) * step; x <= hi.x(); x += step) {
    const int px = ml + static_cast<int>(view.ToPixel({x, 0}).x);
    cv::line(out, {px, mt + image.rows}, {px, mt + image.rows + 5}, dark, 1);
    text(out, fmt::format("{:g}", TickValue(x, step)), {px - 10, mt + image.rows + 20}, dark, 0.45);
  }
  for (double y = std::ceil(lo.y() / step) * step; y <= hi.y(); y += step) {
    const int py = mt + static_cast<int>(view.ToPixel({0, y}).y);
    cv::line(out, {ml - 5, py}, {ml, py}, dark, 1);
    text(out, fmt::format("{:g}", TickValue(y, step)), {5, py + 5}, dark, 0.45);
  }
  text(out, "x (m)", {ml + image.cols / 2 - 20, mt + image.rows + 38}, black, 0.5);
  text(out, "y (m)", {5, mt - 10}, black, 0.5);
  const int bar = static_cast<int>(step * view.px_per_m);
  cv::line(out, {out.cols - mr - bar, mt - 12}, {out.cols - mr, mt - 12}, black, 3);
  text(out, fmt::format("{:g} m", step), {out.cols - mr - bar - 60, mt - 6}, black, 0.45);
  for (size_t i = 0; i < lines.size(); ++i) {
    text(out, lines[i], {5, mt + image.rows + 45 + line_h * static_cast<int>(i) + 12}, dark,
         kCaptionScale);
  }
  return out;
}

}  // namespace fv::field
