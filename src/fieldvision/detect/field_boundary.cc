#include "fieldvision/detect/field_boundary.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "fieldvision/detect/search_area.h"
#include "fieldvision/util/error.h"

namespace fv::detect {

void FieldBoundaryOptions::Check() const {
  FV_REQUIRE(columns >= 2, "FieldBoundaryOptions.columns must be >= 2 (got {})", columns);
  CheckInRange(window_share, 0.0, 1.0, "FieldBoundaryOptions.window_share");
  CheckInRange(min_field_share, 0.0, 1.0, "FieldBoundaryOptions.min_field_share");
  CheckInRange(min_column_share, 0.0, 1.0, "FieldBoundaryOptions.min_column_share");
  image_field.Check();
}

FieldBoundary::FieldBoundary(std::vector<double> xs, std::vector<double> ys)
    : xs_(std::move(xs)), ys_(std::move(ys)) {
  FV_REQUIRE(!xs_.empty() && xs_.size() == ys_.size(),
             "FieldBoundary: {} columns for {} rows (at least one each)", xs_.size(), ys_.size());
  for (size_t i = 1; i < xs_.size(); ++i) {
    FV_REQUIRE(xs_[i] > xs_[i - 1], "FieldBoundary: columns must increase ({} after {})", xs_[i],
               xs_[i - 1]);
  }
}

double FieldBoundary::RowAt(double x) const {
  if (xs_.empty()) return -std::numeric_limits<double>::infinity();
  if (x <= xs_.front()) return ys_.front();
  if (x >= xs_.back()) return ys_.back();
  const size_t i = std::upper_bound(xs_.begin(), xs_.end(), x) - xs_.begin();
  const double t = (x - xs_[i - 1]) / (xs_[i] - xs_[i - 1]);
  return ys_[i - 1] + t * (ys_[i] - ys_[i - 1]);
}

std::string FieldBoundary::Summary() const {
  if (xs_.empty()) return "no field boundary";
  const auto [lo, hi] = std::minmax_element(ys_.begin(), ys_.end());
  return fmt::format("field boundary over columns {:.0f}..{:.0f}, rows {:.0f}..{:.0f}", xs_.front(),
                     xs_.back(), *lo, *hi);
}

namespace {

// The column's spot: the row whose field pixels minus other pixels below it (from the bottom of
// `roi`) are most, or -1 when no row has more field than other pixels below it.
template <typename IsField>
int ColumnSpot(const cv::Rect& roi, const IsField& is_field, long long* field_pixels) {
  int score = 0, best = 0, spot = -1;
  for (int y = roi.y + roi.height - 1; y >= roi.y; --y) {
    const bool field = is_field(y);
    *field_pixels += field;
    score += field ? 1 : -1;
    if (score > best) best = score, spot = y;
  }
  return spot;
}

// The boundary through the spots of the columns `xs` of `roi`, `is_field(i, y)` telling whether
// pixel (xs[i], y) is field; none when too little is.
template <typename IsField>
FieldBoundary BoundaryOfColumns(const std::vector<int>& xs, const cv::Rect& roi,
                                const FieldBoundaryOptions& options, const IsField& is_field) {
  const int n = static_cast<int>(xs.size());
  std::vector<double> centres(n), spots(n);
  long long field_pixels = 0;
  int with_spot = 0;
  for (int i = 0; i < n; ++i) {
    centres[i] = xs[i] + 0.5;
    const int spot = ColumnSpot(
        roi, [&](int y) { return is_field(i, y); }, &field_pixels);
    with_spot += spot >= 0;
    // A column without field bounds nothing: the top of the region.
    spots[i] = spot >= 0 ? spot : roi.y;
  }
  const double sampled = static_cast<double>(n) * roi.height;
  if (field_pixels < options.min_field_share * sampled ||
      with_spot < options.min_column_share * n) {
    return {};
  }
  const int window = static_cast<int>(std::lround(options.window_share * n));
  std::vector<double> ys(n);
  for (int i = 0; i < n; ++i) {
    const auto first = spots.begin() + std::max(0, i - window);
    const auto last = spots.begin() + std::min(n, i + window + 1);
    ys[i] = *std::min_element(first, last);
  }
  return FieldBoundary(std::move(centres), std::move(ys));
}

}  // namespace

FieldBoundary FindFieldBoundary(const cv::Mat& bgr, const ColourTable& table, uint8_t field_bit,
                                const FieldBoundaryOptions& options, const cv::Rect& roi_in) {
  options.Check();
  FV_REQUIRE(bgr.type() == CV_8UC3, "field boundary: the image must be 8-bit BGR");
  const cv::Rect roi = SearchArea(bgr.size(), roi_in);
  if (roi.width < 2 || roi.height < 2) return {};
  const int n = std::min(options.columns, roi.width);
  std::vector<int> xs(n);
  for (int i = 0; i < n; ++i) {
    xs[i] = roi.x + static_cast<int>(std::lround((i + 0.5) * roi.width / n - 0.5));
  }
  if (field_bit != 0) {
    FieldBoundary b = BoundaryOfColumns(xs, roi, options, [&](int i, int y) {
      const uint8_t* p = bgr.ptr<uint8_t>(y) + 3 * static_cast<ptrdiff_t>(xs[i]);
      return (table.Classify(p[0], p[1], p[2]) & field_bit) != 0;
    });
    if (b.valid()) return b;
  }
  // The class finds too little field: the image's own field colour (image_field.h).
  const std::optional<ImageFieldColour> colour =
      FindImageFieldColour(bgr, roi, options.image_field);
  if (!colour) return {};
  std::vector<int> rows(roi.height);
  for (int k = 0; k < roi.height; ++k) rows[k] = roi.y + k;
  const cv::Mat lab = LabAt(bgr, xs, rows);
  return BoundaryOfColumns(xs, roi, options, [&](int i, int y) {
    return colour->Holds(lab.at<cv::Vec3b>(y - roi.y, i));
  });
}

}  // namespace fv::detect
