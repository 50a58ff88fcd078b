#include "fieldvision/detect/field_surround.h"

#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/lab.h"
#include "fieldvision/detect/search_area.h"
#include "fieldvision/util/error.h"

namespace fv::detect {

void FieldSurroundOptions::Check() const {
  CheckNonNegative(gap_px, "FieldSurroundOptions.gap_px");
  FV_REQUIRE(width_px >= 1.0, "FieldSurroundOptions.width_px must be >= 1 (got {})", width_px);
  CheckInRange(min_share, 0.0, 1.0, "FieldSurroundOptions.min_share");
}

double FieldShareAround(const cv::Mat& bgr, const ColourTable& table, uint8_t field_bits,
                        const ImageFieldColour* image_field, const Eigen::Vector2d& centre_px,
                        double radius_px, const FieldSurroundOptions& o, const cv::Rect& roi) {
  o.Check();
  FV_REQUIRE(bgr.type() == CV_8UC3, "field surround: the image must be 8-bit BGR");
  FV_REQUIRE(std::isfinite(centre_px.x()) && std::isfinite(centre_px.y()) &&
                 std::isfinite(radius_px) && radius_px >= 0,
             "field surround: bad spot ({}, {}), radius {}", centre_px.x(), centre_px.y(),
             radius_px);
  const double r_in = radius_px + o.gap_px, r_out = r_in + o.width_px;
  const int x0 = static_cast<int>(std::floor(centre_px.x() - r_out));
  const int x1 = static_cast<int>(std::ceil(centre_px.x() + r_out));
  const int y0 = static_cast<int>(std::floor(centre_px.y() - r_out));
  const int y1 = static_cast<int>(std::ceil(centre_px.y() + r_out));
  const cv::Rect area = SearchArea(bgr.size(), roi);
  std::vector<cv::Vec3b> ring;
  for (int y = std::max(area.y, y0); y <= std::min(area.y + area.height - 1, y1); ++y) {
    const auto* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = std::max(area.x, x0); x <= std::min(area.x + area.width - 1, x1); ++x) {
      const double d = std::hypot(x - centre_px.x(), y - centre_px.y());
      if (d >= r_in && d <= r_out) ring.push_back(row[x]);
    }
  }
  if (ring.empty()) return -1.0;
  cv::Mat lab;
  if (image_field != nullptr) {
    BgrToLab(cv::Mat(1, static_cast<int>(ring.size()), CV_8UC3, ring.data()), &lab);
  }
  int field = 0;
  for (size_t i = 0; i < ring.size(); ++i) {
    const cv::Vec3b& p = ring[i];
    const bool in_class = (table.Classify(p[0], p[1], p[2]) & field_bits) != 0;
    field += in_class ||
             (image_field != nullptr && image_field->Holds(lab.at<cv::Vec3b>(static_cast<int>(i))));
  }
  return static_cast<double>(field) / static_cast<double>(ring.size());
}

}  // namespace fv::detect
