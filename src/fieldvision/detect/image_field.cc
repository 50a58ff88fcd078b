#include "fieldvision/detect/image_field.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/lab.h"
#include "fieldvision/detect/search_area.h"
#include "fieldvision/util/error.h"

namespace fv::detect {

void ImageFieldOptions::Check() const {
  CheckInRange(lower_share, 0.0, 1.0, "ImageFieldOptions.lower_share");
  FV_REQUIRE(lower_share > 0, "ImageFieldOptions.lower_share must be > 0");
  FV_REQUIRE(samples >= 1, "ImageFieldOptions.samples must be >= 1 (got {})", samples);
  CheckInRange(min_share, 0.0, 1.0, "ImageFieldOptions.min_share");
  CheckNonNegative(max_delta_l, "ImageFieldOptions.max_delta_l");
  CheckNonNegative(max_delta_ab, "ImageFieldOptions.max_delta_ab");
}

bool ImageFieldColour::Holds(const cv::Vec3b& p) const {
  const double dl = p[0] - lab[0], da = p[1] - lab[1], db = p[2] - lab[2];
  return std::abs(dl) <= max_delta_l && da * da + db * db <= max_delta_ab * max_delta_ab;
}

cv::Mat LabAt(const cv::Mat& bgr, const std::vector<int>& xs, const std::vector<int>& ys) {
  FV_REQUIRE(bgr.type() == CV_8UC3, "image field: the image must be 8-bit BGR");
  cv::Mat gathered(static_cast<int>(ys.size()), static_cast<int>(xs.size()), CV_8UC3);
  for (size_t j = 0; j < ys.size(); ++j) {
    const auto* src = bgr.ptr<cv::Vec3b>(ys[j]);
    auto* dst = gathered.ptr<cv::Vec3b>(static_cast<int>(j));
    for (size_t i = 0; i < xs.size(); ++i) dst[i] = src[xs[i]];
  }
  cv::Mat lab;
  BgrToLab(gathered, &lab);
  return lab;
}

std::optional<ImageFieldColour> FindImageFieldColour(const cv::Mat& bgr, const cv::Rect& roi_in,
                                                     const ImageFieldOptions& o) {
  o.Check();
  FV_REQUIRE(bgr.type() == CV_8UC3, "image field: the image must be 8-bit BGR");
  const cv::Rect roi = SearchArea(bgr.size(), roi_in);
  if (!o.enabled || roi.empty()) return std::nullopt;
  const int top = roi.y + static_cast<int>(std::floor((1.0 - o.lower_share) * roi.height));
  const double lower_area = static_cast<double>(roi.width) * (roi.y + roi.height - top);
  const int step = std::max(1, static_cast<int>(std::lround(std::sqrt(lower_area / o.samples))));
  std::vector<int> xs, ys;
  for (int x = roi.x + step / 2; x < roi.x + roi.width; x += step) xs.push_back(x);
  for (int y = top + step / 2; y < roi.y + roi.height; y += step) ys.push_back(y);
  const cv::Mat lab = LabAt(bgr, xs, ys);
  if (lab.empty()) return std::nullopt;
  // The most common colour: a histogram of L / 16, a / 6, b / 6 bins, then the mean of its bin.
  constexpr size_t kL = 16, kAb = 43;
  const auto key = [](const cv::Vec3b& p) {
    return ((size_t{p[0]} / 16) * kAb + p[1] / 6) * kAb + p[2] / 6;
  };
  std::vector<int> counts(kL * kAb * kAb, 0);
  for (int j = 0; j < lab.rows; ++j) {
    for (int i = 0; i < lab.cols; ++i) ++counts[key(lab.at<cv::Vec3b>(j, i))];
  }
  const auto best_key =
      static_cast<size_t>(std::max_element(counts.begin(), counts.end()) - counts.begin());
  const int best_count = counts[best_key];
  cv::Vec3d sum(0, 0, 0);
  for (int j = 0; j < lab.rows; ++j) {
    for (int i = 0; i < lab.cols; ++i) {
      const cv::Vec3b& p = lab.at<cv::Vec3b>(j, i);
      if (key(p) == best_key) sum += cv::Vec3d(p[0], p[1], p[2]);
    }
  }
  ImageFieldColour colour;
  colour.lab = cv::Vec3f(sum / best_count);
  colour.max_delta_l = o.max_delta_l;
  colour.max_delta_ab = o.max_delta_ab;
  long long near = 0;
  for (int j = 0; j < lab.rows; ++j) {
    for (int i = 0; i < lab.cols; ++i) near += colour.Holds(lab.at<cv::Vec3b>(j, i));
  }
  if (near < o.min_share * static_cast<double>(lab.total())) return std::nullopt;
  return colour;
}

}  // namespace fv::detect
