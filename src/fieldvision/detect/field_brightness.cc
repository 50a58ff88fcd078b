#include "fieldvision/detect/field_brightness.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "fieldvision/detect/search_area.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace fv::detect {

void FieldBrightnessOptions::Check() const {
  FV_REQUIRE(step_px >= 1, "FieldBrightnessOptions.step_px must be >= 1 (got {})", step_px);
  CheckInRange(min_field_share, 0.0, 1.0, "FieldBrightnessOptions.min_field_share");
  FV_REQUIRE(min_field_samples >= 1, "FieldBrightnessOptions.min_field_samples must be >= 1");
  FV_REQUIRE(max_disc_samples >= 1, "FieldBrightnessOptions.max_disc_samples must be >= 1");
  image_field.Check();
}

namespace {

uint8_t Value(const cv::Mat& bgr, int x, int y) {
  const uint8_t* p = bgr.ptr<uint8_t>(y) + 3 * static_cast<ptrdiff_t>(x);
  return std::max({p[0], p[1], p[2]});
}

std::vector<double> AsDoubles(const std::vector<uint8_t>& v) { return {v.begin(), v.end()}; }

}  // namespace

double FieldValue(const cv::Mat& bgr, const ColourTable& table, uint8_t field_bit,
                  const FieldBrightnessOptions& o, const cv::Rect& roi_in) {
  o.Check();
  FV_REQUIRE(bgr.type() == CV_8UC3, "field brightness: the image must be 8-bit BGR");
  const cv::Rect roi = SearchArea(bgr.size(), roi_in);
  if (roi.empty()) return -1.0;
  std::vector<int> xs, ys;
  for (int x = roi.x + o.step_px / 2; x < roi.x + roi.width; x += o.step_px) xs.push_back(x);
  for (int y = roi.y + o.step_px / 2; y < roi.y + roi.height; y += o.step_px) ys.push_back(y);
  const double samples = static_cast<double>(xs.size()) * static_cast<double>(ys.size());
  const auto enough = [&](const std::vector<uint8_t>& v) {
    const auto n = static_cast<long long>(v.size());
    return n >= o.min_field_samples && n >= o.min_field_share * samples;
  };
  std::vector<uint8_t> values;
  if (field_bit != 0) {
    for (const int y : ys) {
      for (const int x : xs) {
        const uint8_t* p = bgr.ptr<uint8_t>(y) + 3 * static_cast<ptrdiff_t>(x);
        if ((table.Classify(p[0], p[1], p[2]) & field_bit) != 0) values.push_back(Value(bgr, x, y));
      }
    }
    if (enough(values)) return util::Median(AsDoubles(values));
  }
  // The class finds too little field: the image's own field colour (image_field.h).
  const std::optional<ImageFieldColour> colour = FindImageFieldColour(bgr, roi, o.image_field);
  if (!colour) return -1.0;
  const cv::Mat lab = LabAt(bgr, xs, ys);
  values.clear();
  for (size_t j = 0; j < ys.size(); ++j) {
    for (size_t i = 0; i < xs.size(); ++i) {
      if (colour->Holds(lab.at<cv::Vec3b>(static_cast<int>(j), static_cast<int>(i)))) {
        values.push_back(Value(bgr, xs[i], ys[j]));
      }
    }
  }
  return enough(values) ? util::Median(AsDoubles(values)) : -1.0;
}

double LitValue(const cv::Mat& bgr, const Eigen::Vector2d& centre_px, double radius_px,
                const FieldBrightnessOptions& o) {
  FV_REQUIRE(bgr.type() == CV_8UC3, "field brightness: the image must be 8-bit BGR");
  FV_REQUIRE(
      std::isfinite(centre_px.x()) && std::isfinite(centre_px.y()) && std::isfinite(radius_px),
      "field brightness: non-finite disc");
  const double r = std::max(radius_px, 0.5);
  const double area = M_PI * r * r;
  const int step = std::max(1, static_cast<int>(std::sqrt(area / o.max_disc_samples)));
  const int x0 = std::max(0, static_cast<int>(std::floor(centre_px.x() - r)));
  const int x1 = std::min(bgr.cols - 1, static_cast<int>(std::ceil(centre_px.x() + r)));
  const int y0 = std::max(0, static_cast<int>(std::floor(centre_px.y() - r)));
  const int y1 = std::min(bgr.rows - 1, static_cast<int>(std::ceil(centre_px.y() + r)));
  std::vector<uint8_t> values;
  for (int y = y0; y <= y1; y += step) {
    for (int x = x0; x <= x1; x += step) {
      const double dx = x - centre_px.x(), dy = y - centre_px.y();
      if (dx * dx + dy * dy <= r * r) values.push_back(Value(bgr, x, y));
    }
  }
  if (values.empty()) {
    // A disc smaller than a pixel: the pixel under its centre.
    const int x = static_cast<int>(std::floor(centre_px.x()));
    const int y = static_cast<int>(std::floor(centre_px.y()));
    if (x < 0 || y < 0 || x >= bgr.cols || y >= bgr.rows) return -1.0;
    return Value(bgr, x, y);
  }
  return util::RankPercentile(AsDoubles(values), 0.9);
}

}  // namespace fv::detect
