#include "fieldvision/detect/background.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"

namespace fv::detect {

namespace {

constexpr double kDiscRadii = 0.8;
constexpr double kRingInnerRadii = 1.5;
constexpr double kRingOuterRadii = 2.2;

int LargestDifference(const cv::Vec3b& a, const cv::Vec3b& b) {
  return std::max({std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])});
}

// Sorts each pixel's and channel's values across `frames` in place (an odd-even transposition
// sort of whole images: n rounds of compare-exchanges, each a vectorised min and max, several
// times faster than sorting each pixel's values): frame k then holds every pixel's k-th smallest
// value, the middle one the median (the lower one for even counts).
void SortPixelwise(std::vector<cv::Mat>* frames) {
  std::vector<cv::Mat>& v = *frames;
  const size_t n = v.size();
  cv::Mat low;
  for (size_t round = 0; round < n; ++round) {
    for (size_t i = round % 2; i + 1 < n; i += 2) {
      cv::min(v[i], v[i + 1], low);
      cv::max(v[i], v[i + 1], v[i + 1]);
      std::swap(v[i], low);
    }
  }
}

}  // namespace

void BackgroundOptions::Check() const {
  CheckInRange(samples, 3, 99, "samples");
  FV_REQUIRE(scale == 1 || scale == 2, "scale must be 1 or 2 (got {})", scale);
  CheckInRange(min_difference, 1.0, 255.0, "min_difference");
  CheckNonNegative(noise_factor, "noise_factor");
  CheckNonNegative(max_noise, "max_noise");
  CheckInRange(max_changed_share, 0.0, 1.0, "max_changed_share");
  CheckInRange(min_disc_share, 0.0, 1.0, "min_disc_share");
  CheckInRange(max_ring_share, 0.0, 1.0, "max_ring_share");
  CheckInRange(min_round_fill, 0.0, 1.0, "min_round_fill");
}

cv::Mat Background::Reduce(const cv::Mat& bgr, int scale) {
  if (scale == 1) return bgr.clone();
  cv::Mat out;
  const cv::Rect even(0, 0, bgr.cols / scale * scale, bgr.rows / scale * scale);
  cv::resize(bgr(even), out, cv::Size(even.width / scale, even.height / scale), 0, 0,
             cv::INTER_AREA);
  return out;
}

Background::Background(std::vector<cv::Mat>&& frames, const cv::Size& full_size,
                       const BackgroundOptions& options)
    : options_(options), full_size_(full_size) {
  options_.Check();
  FV_REQUIRE(frames.size() >= 3, "a background needs at least 3 frames, got {}", frames.size());
  const cv::Size reduced(full_size.width / options_.scale, full_size.height / options_.scale);
  for (const cv::Mat& f : frames) {
    FV_REQUIRE(f.type() == CV_8UC3 && f.size() == reduced,
               "background frames must be BGR images of {}x{} (got {}x{})", reduced.width,
               reduced.height, f.cols, f.rows);
  }
  // Sorted in place: per pixel and channel the sorted values differ from the median as the
  // frames' values do.
  SortPixelwise(&frames);
  image_ = frames[(frames.size() - 1) / 2].clone();
  // Noise: the median of the samples' per-channel differences from the background.
  std::array<long long, 256> histogram{};
  long long total = 0;
  cv::Mat diff;  // reused: fresh pages cost more than the arithmetic
  for (const cv::Mat& f : frames) {
    cv::absdiff(f, image_, diff);
    for (int y = 0; y < diff.rows; ++y) {
      const uint8_t* p = diff.ptr<uint8_t>(y);
      for (int x = 0; x < 3 * diff.cols; ++x) ++histogram[p[x]];
    }
  }
  for (long long h : histogram) total += h;
  long long below = 0;
  int median = 0;
  while (median < 255 && 2 * (below + histogram[median]) < total) below += histogram[median++];
  noise_ = median;
  threshold_ = std::max(options_.min_difference, options_.noise_factor * noise_);
  long long changed = 0;
  for (int d = static_cast<int>(std::ceil(threshold_)); d < 256; ++d) changed += histogram[d];
  changed_share_ = total > 0 ? static_cast<double>(changed) / total : 1.0;
  usable_ = noise_ <= options_.max_noise && changed_share_ <= options_.max_changed_share;
}

bool Background::Changed(const cv::Vec3b& a, const cv::Vec3b& b) const {
  return LargestDifference(a, b) >= threshold_;
}

BackgroundEvidence Background::Compare(const cv::Mat& bgr, const Eigen::Vector2d& centre_px,
                                       double radius_px, const cv::Rect& roi) const {
  FV_REQUIRE(bgr.type() == CV_8UC3, "background: the frame must be 8-bit BGR");
  BackgroundEvidence out;
  // A frame of another size than the sampled video's says nothing against it.
  if (bgr.size() != full_size_ || !usable_ || !(radius_px > 0) || !centre_px.allFinite()) {
    return out;
  }
  const int k = options_.scale;
  const Eigen::Vector2d c = (centre_px + Eigen::Vector2d::Constant(0.5)) / k -
                            Eigen::Vector2d::Constant(0.5);  // pixel centres
  const double r = radius_px / k;
  const double reach = kRingOuterRadii * r;
  const double full_reach = kRingOuterRadii * radius_px;
  const cv::Rect box =
      ReducedInside(cv::Rect(static_cast<int>(std::floor(centre_px.x() - full_reach)),
                             static_cast<int>(std::floor(centre_px.y() - full_reach)),
                             static_cast<int>(std::ceil(2 * full_reach)) + 2,
                             static_cast<int>(std::ceil(2 * full_reach)) + 2),
                    roi);
  if (box.empty()) return out;
  const cv::Mat frame = ReducedPart(bgr, box);
  const double disc2 = std::pow(kDiscRadii * r, 2);
  const double inner2 = std::pow(kRingInnerRadii * r, 2);
  const double outer2 = reach * reach;
  long long disc = 0, disc_changed = 0, ring = 0, ring_changed = 0;
  for (int y = 0; y < box.height; ++y) {
    const auto* a = frame.ptr<cv::Vec3b>(y);
    const auto* b = image_.ptr<cv::Vec3b>(box.y + y) + box.x;
    const double dy = box.y + y - c.y();
    for (int x = 0; x < box.width; ++x) {
      const double dx = box.x + x - c.x();
      const double d2 = dx * dx + dy * dy;
      if (d2 < disc2) {
        ++disc;
        disc_changed += Changed(a[x], b[x]);
      } else if (d2 >= inner2 && d2 <= outer2) {
        ++ring;
        ring_changed += Changed(a[x], b[x]);
      }
    }
  }
  // Enough of both read: half of each area and a few pixels.
  const double disc_area = M_PI * disc2;
  const double ring_area = M_PI * (outer2 - inner2);
  if (disc < std::max(3.0, 0.5 * disc_area) || ring < std::max(8.0, 0.5 * ring_area)) return out;
  out.measured = true;
  out.disc_share = static_cast<double>(disc_changed) / disc;
  out.ring_share = static_cast<double>(ring_changed) / ring;
  out.apart =
      out.disc_share >= options_.min_disc_share && out.ring_share <= options_.max_ring_share;
  return out;
}

cv::Mat Background::ReducedPart(const cv::Mat& bgr, const cv::Rect& reduced) const {
  const int k = options_.scale;
  return Reduce(bgr(cv::Rect(reduced.x * k, reduced.y * k, reduced.width * k, reduced.height * k)),
                k);
}

cv::Rect Background::ReducedInside(const cv::Rect& box, const cv::Rect& roi) const {
  const int k = options_.scale;
  const cv::Rect frame(0, 0, full_size_.width, full_size_.height);
  const cv::Rect limit = (roi.empty() ? frame : (roi & frame)) & box;
  if (limit.empty()) return {};
  const int x0 = (limit.x + k - 1) / k, y0 = (limit.y + k - 1) / k;
  const int x1 = (limit.x + limit.width) / k, y1 = (limit.y + limit.height) / k;
  if (x1 <= x0 || y1 <= y0) return {};
  return cv::Rect(x0, y0, x1 - x0, y1 - y0) & cv::Rect(0, 0, image_.cols, image_.rows);
}

std::optional<Background::Circle> Background::ChangedDisc(const cv::Mat& bgr, const cv::Rect& box,
                                                          const cv::Rect& roi) const {
  FV_REQUIRE(bgr.type() == CV_8UC3, "background: the frame must be 8-bit BGR");
  const int k = options_.scale;
  const cv::Rect reduced = ReducedInside(box, roi);
  if (bgr.size() != full_size_ || !usable_ || reduced.width < 3 || reduced.height < 3) {
    return std::nullopt;
  }
  const cv::Mat frame = ReducedPart(bgr, reduced);
  cv::Mat changed(reduced.size(), CV_8U);
  for (int y = 0; y < reduced.height; ++y) {
    const auto* a = frame.ptr<cv::Vec3b>(y);
    const auto* b = image_.ptr<cv::Vec3b>(reduced.y + y) + reduced.x;
    uint8_t* m = changed.ptr<uint8_t>(y);
    for (int x = 0; x < reduced.width; ++x) m[x] = Changed(a[x], b[x]) ? 255 : 0;
  }
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(changed, labels, stats, centroids, 8, CV_32S);
  int best = 0;
  for (int i = 1; i < n; ++i) {
    if (best == 0 || stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) {
      best = i;
    }
  }
  if (best == 0 || stats.at<int>(best, cv::CC_STAT_AREA) < 5) return std::nullopt;
  std::vector<cv::Point> points;
  cv::findNonZero(labels == best, points);
  cv::Point2f enclosing_centre;
  float enclosing_r = 0;
  cv::minEnclosingCircle(points, enclosing_centre, enclosing_r);
  const double area = stats.at<int>(best, cv::CC_STAT_AREA);
  // Pixel centres: the enclosing circle passes through them, the area's edge lies half a pixel
  // out.
  const double fill = area / (M_PI * std::pow(enclosing_r + 0.5, 2));
  if (fill < options_.min_round_fill) return std::nullopt;
  const Eigen::Vector2d centre(reduced.x + centroids.at<double>(best, 0),
                               reduced.y + centroids.at<double>(best, 1));
  return Circle{(centre + Eigen::Vector2d::Constant(0.5)) * k - Eigen::Vector2d::Constant(0.5),
                std::sqrt(area / M_PI) * k};
}

std::string Background::Summary() const {
  return fmt::format(
      "background {}x{} (1/{} scale): noise {:.0f}, changed at {:.0f}, {:.1f} % of "
      "the sampled values changed{}",
      image_.cols, image_.rows, options_.scale, noise_, threshold_, 100 * changed_share_,
      usable_ ? "" : " (not usable: the camera moves or the light changes)");
}

}  // namespace fv::detect
