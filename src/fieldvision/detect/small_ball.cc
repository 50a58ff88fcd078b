#include "fieldvision/detect/small_ball.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"

namespace fv::detect {

void SmallBallOptions::Check() const {
  FV_REQUIRE(mode == "auto" || mode == "on" || mode == "off",
             "small balls: mode must be auto, on or off (got '{}')", mode);
  FV_REQUIRE(inner_box_px >= 3 && inner_box_px % 2 == 1 && outer_box_px > inner_box_px + 1 &&
                 outer_box_px % 2 == 1 && outer_box_px <= 31,
             "SmallBallOptions: boxes must be odd with 3 <= inner_box_px < outer_box_px - 1 <= 30 "
             "(got {}, {})",
             inner_box_px, outer_box_px);
  FV_REQUIRE(!extensions.empty(), "SmallBallOptions.extensions is empty");
  for (const double t : extensions) CheckInRange(t, 1.0, 10.0, "SmallBallOptions.extensions");
  CheckPositive(min_contrast, "SmallBallOptions.min_contrast");
  CheckNonNegative(noise_level, "SmallBallOptions.noise_level");
  CheckPositive(max_radius_px, "SmallBallOptions.max_radius_px");
  FV_REQUIRE(max_spots >= 1, "SmallBallOptions.max_spots must be at least 1 (got {})", max_spots);
}

namespace {

// Per-thread images of a frame's size: allocating them anew for every frame cost more than the
// filters (fresh pages, each faulted in).
struct Scratch {
  cv::Mat spot, big, small;     // unnormalised box sums (32-bit) of the 3x3, outer and inner boxes
  cv::Mat contrast, extension;  // per pixel (0: no spot)
};

// The summed variance of the three channels over the ring between the inner and outer boxes
// around (x, y) of `img` (borders replicated), about `mean`.
double RingVariance(const cv::Mat& img, int x, int y, int inner_half, int outer_half,
                    const cv::Vec3f& mean) {
  double sum = 0;
  int n = 0;
  for (int dy = -outer_half; dy <= outer_half; ++dy) {
    const auto* row = img.ptr<cv::Vec3b>(std::clamp(y + dy, 0, img.rows - 1));
    for (int dx = -outer_half; dx <= outer_half; ++dx) {
      if (std::abs(dx) <= inner_half && std::abs(dy) <= inner_half) continue;
      const cv::Vec3b& p = row[std::clamp(x + dx, 0, img.cols - 1)];
      for (int ch = 0; ch < 3; ++ch) {
        const double e = p[ch] - mean[ch];
        sum += e * e;
      }
      ++n;
    }
  }
  return sum / n;
}

// The smallest extension t (o.extensions in order) at which ring + t (spot - ring) is in the
// class, or 0.
float Extension(const ColourTable& table, uint8_t bit, const cv::Vec3f& ring, const cv::Vec3f& d,
                const SmallBallOptions& o) {
  for (const double t : o.extensions) {
    uint8_t u[3];
    for (int ch = 0; ch < 3; ++ch) u[ch] = cv::saturate_cast<uint8_t>(ring[ch] + t * d[ch]);
    if ((table.Classify(u[0], u[1], u[2]) & bit) != 0) return static_cast<float>(t);
  }
  return 0.0F;
}

struct Peak {
  float k;
  int x, y;
};

// The spot at a peak: contrast-weighted centre over 3x3; radius from the ball's share alpha of
// each pixel within the inner box (the projection of pixel - background on ball - background),
// summed into an area.
SmallBall MeasureSpot(const cv::Mat& img, const Scratch& s, const Peak& pk, const cv::Point& tl,
                      int n_ring, const SmallBallOptions& o) {
  SmallBall b;
  b.contrast = pk.k;
  b.extension = s.extension.at<float>(pk.y, pk.x);
  double wx = 0, wy = 0, w = 0;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = pk.x + dx, y = pk.y + dy;
      if (x < 0 || y < 0 || x >= img.cols || y >= img.rows) continue;
      const double k = s.contrast.at<float>(y, x);
      wx += k * x, wy += k * y, w += k;
    }
  }
  b.centre_px = Eigen::Vector2d(tl.x + wx / w, tl.y + wy / w);
  const cv::Vec3i big = s.big.at<cv::Vec3i>(pk.y, pk.x), small = s.small.at<cv::Vec3i>(pk.y, pk.x);
  const cv::Vec3i spot = s.spot.at<cv::Vec3i>(pk.y, pk.x);
  cv::Vec3f bg, ball_minus_bg;
  for (int ch = 0; ch < 3; ++ch) {
    bg[ch] = static_cast<float>(double(big[ch] - small[ch]) / n_ring);
    ball_minus_bg[ch] = static_cast<float>(b.extension * (spot[ch] / 9.0 - bg[ch]));
  }
  const double norm2 = ball_minus_bg.dot(ball_minus_bg);
  double area = 0;
  const int h = o.inner_box_px / 2;
  for (int y = std::max(0, pk.y - h); y <= std::min(img.rows - 1, pk.y + h); ++y) {
    for (int x = std::max(0, pk.x - h); x <= std::min(img.cols - 1, pk.x + h); ++x) {
      const cv::Vec3f px = cv::Vec3f(img.at<cv::Vec3b>(y, x)) - bg;
      area += std::clamp(px.dot(ball_minus_bg) / norm2, 0.0, 1.0);
    }
  }
  b.radius_px = std::sqrt(area / M_PI);
  return b;
}

}  // namespace

std::vector<SmallBall> FindSmallBalls(const cv::Mat& bgr, const ColourTable& table, uint8_t bit,
                                      const cv::Rect& roi, const cv::Mat& mask,
                                      const SmallBallOptions& o) {
  std::vector<SmallBall> out;
  const int pad = o.outer_box_px / 2 + 1;
  const cv::Rect image(0, 0, bgr.cols, bgr.rows);
  const cv::Rect win =
      cv::Rect(roi.x - pad, roi.y - pad, roi.width + 2 * pad, roi.height + 2 * pad) & image;
  if (win.width < o.outer_box_px || win.height < o.outer_box_px) return out;
  const cv::Mat img = bgr(win);
  thread_local Scratch s;
  // Spot: 3x3 mean; background: the ring between the inner and outer boxes (mean and spread).
  // Integer box sums (exact) of the 8-bit image; the spread only where a spot can stand out.
  const cv::Size outer(o.outer_box_px, o.outer_box_px), inner(o.inner_box_px, o.inner_box_px);
  cv::boxFilter(img, s.spot, CV_32S, {3, 3}, {-1, -1}, false, cv::BORDER_REPLICATE);
  cv::boxFilter(img, s.big, CV_32S, outer, {-1, -1}, false, cv::BORDER_REPLICATE);
  cv::boxFilter(img, s.small, CV_32S, inner, {-1, -1}, false, cv::BORDER_REPLICATE);
  const int n_ring = outer.area() - inner.area();
  s.contrast.create(win.size(), CV_32F);
  s.contrast.setTo(0);
  s.extension.create(win.size(), CV_32F);
  // e = 9 n_ring (spot - ring) in integers (exact, and exact as floats and their squares as
  // doubles). |spot - ring| / (spread + noise) >= min_contrast needs |spot - ring| >= min_contrast
  // x noise: a row's squares in float first (a loop the compiler vectorises), the exact ones only
  // where they may pass, the spread only where the colour reaches the class.
  const double scale = 9.0 * n_ring;
  const double min_scaled2 =
      o.min_contrast * o.noise_level * o.min_contrast * o.noise_level * scale * scale;
  const float pre_threshold = static_cast<float>(0.999 * min_scaled2);
  const cv::Rect searched = roi & win;
  std::vector<float> row_e(3 * static_cast<size_t>(searched.width));
  std::vector<Peak> hits;
  for (int gy = searched.y; gy < searched.y + searched.height; ++gy) {
    const int y = gy - win.y;
    const int x0 = searched.x - win.x;
    const int* sp = s.spot.ptr<int>(y) + 3 * static_cast<ptrdiff_t>(x0);
    const int* b = s.big.ptr<int>(y) + 3 * static_cast<ptrdiff_t>(x0);
    const int* sm = s.small.ptr<int>(y) + 3 * static_cast<ptrdiff_t>(x0);
    const uint8_t* m = mask.empty() ? nullptr : mask.ptr<uint8_t>(gy);
    for (size_t i = 0; i < row_e.size(); ++i) {
      row_e[i] = static_cast<float>(sp[i] * n_ring - 9 * (b[i] - sm[i]));
    }
    for (int gx = searched.x; gx < searched.x + searched.width; ++gx) {
      const size_t i = 3 * static_cast<size_t>(gx - searched.x);
      const float* e = &row_e[i];
      if (e[0] * e[0] + e[1] * e[1] + e[2] * e[2] < pre_threshold) continue;
      const double scaled2 = double(e[0]) * e[0] + double(e[1]) * e[1] + double(e[2]) * e[2];
      if (scaled2 < min_scaled2 || (m != nullptr && m[gx] == 0)) continue;
      cv::Vec3f ring, d;
      for (int ch = 0; ch < 3; ++ch) {
        ring[ch] = static_cast<float>(double(b[i + ch] - sm[i + ch]) / n_ring);
        d[ch] = static_cast<float>(e[ch] / scale);
      }
      const int x = gx - win.x;
      const float t = Extension(table, bit, ring, d, o);
      if (t == 0.0F) continue;
      const double var = RingVariance(img, x, y, o.inner_box_px / 2, o.outer_box_px / 2, ring);
      const double k = std::sqrt(scaled2) / scale / (std::sqrt(var) + o.noise_level);
      if (k < o.min_contrast) continue;
      s.contrast.at<float>(y, x) = static_cast<float>(k);
      s.extension.at<float>(y, x) = t;
      hits.push_back({static_cast<float>(k), x, y});
    }
  }
  // Local maxima (5x5) of the contrast, strongest first.
  std::vector<Peak> found;
  for (const Peak& h : hits) {
    bool peak = true;
    for (int dy = -2; dy <= 2 && peak; ++dy) {
      for (int dx = -2; dx <= 2 && peak; ++dx) {
        const int x = h.x + dx, y = h.y + dy;
        if (x < 0 || y < 0 || x >= win.width || y >= win.height) continue;
        peak = s.contrast.at<float>(y, x) <= h.k;
      }
    }
    if (peak) found.push_back(h);
  }
  std::stable_sort(found.begin(), found.end(),
                   [](const Peak& a, const Peak& b) { return a.k > b.k; });
  for (const Peak& pk : found) {
    if (static_cast<int>(out.size()) >= o.max_spots) break;
    const SmallBall b = MeasureSpot(img, s, pk, win.tl(), n_ring, o);
    if (b.radius_px > o.max_radius_px) continue;
    out.push_back(b);
  }
  return out;
}

}  // namespace fv::detect
