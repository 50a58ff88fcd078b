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

std::vector<SmallBall> FindSmallBalls(const cv::Mat& bgr, const ColourTable& table, uint8_t bit,
                                      const cv::Rect& roi, const cv::Mat& mask,
                                      const SmallBallOptions& o) {
  std::vector<SmallBall> out;
  const int pad = o.outer_box_px / 2 + 1;
  const cv::Rect image(0, 0, bgr.cols, bgr.rows);
  const cv::Rect win =
      cv::Rect(roi.x - pad, roi.y - pad, roi.width + 2 * pad, roi.height + 2 * pad) & image;
  if (win.width < o.outer_box_px || win.height < o.outer_box_px) return out;
  cv::Mat f, f2;
  bgr(win).convertTo(f, CV_32FC3);
  cv::multiply(f, f, f2);
  // Spot: 3x3 mean; background: the ring between the inner and outer boxes (mean and spread).
  cv::Mat spot, big, small, big2, small2;
  cv::blur(f, spot, {3, 3}, {-1, -1}, cv::BORDER_REPLICATE);
  const cv::Size outer(o.outer_box_px, o.outer_box_px), inner(o.inner_box_px, o.inner_box_px);
  cv::boxFilter(f, big, -1, outer, {-1, -1}, false, cv::BORDER_REPLICATE);
  cv::boxFilter(f, small, -1, inner, {-1, -1}, false, cv::BORDER_REPLICATE);
  cv::boxFilter(f2, big2, -1, outer, {-1, -1}, false, cv::BORDER_REPLICATE);
  cv::boxFilter(f2, small2, -1, inner, {-1, -1}, false, cv::BORDER_REPLICATE);
  const double n_ring = double(outer.area() - inner.area());
  cv::Mat contrast(win.size(), CV_32F, cv::Scalar(0));
  cv::Mat extension(win.size(), CV_32F, cv::Scalar(0));
  cv::Mat background(win.size(), CV_32FC3);
  for (int y = 0; y < win.height; ++y) {
    const int gy = win.y + y;
    const cv::Vec3f* s = spot.ptr<cv::Vec3f>(y);
    const cv::Vec3f* b = big.ptr<cv::Vec3f>(y);
    const cv::Vec3f* sm = small.ptr<cv::Vec3f>(y);
    const cv::Vec3f* b2 = big2.ptr<cv::Vec3f>(y);
    const cv::Vec3f* s2 = small2.ptr<cv::Vec3f>(y);
    float* c = contrast.ptr<float>(y);
    float* e = extension.ptr<float>(y);
    cv::Vec3f* bg = background.ptr<cv::Vec3f>(y);
    const uint8_t* m = mask.empty() ? nullptr : mask.ptr<uint8_t>(gy);
    for (int x = 0; x < win.width; ++x) {
      const int gx = win.x + x;
      if (!roi.contains({gx, gy}) || (m != nullptr && m[gx] == 0)) continue;
      double var = 0, diff2 = 0;
      cv::Vec3f ring, d;
      for (int ch = 0; ch < 3; ++ch) {
        ring[ch] = static_cast<float>((b[x][ch] - sm[x][ch]) / n_ring);
        var += std::max(0.0, (b2[x][ch] - s2[x][ch]) / n_ring - double(ring[ch]) * ring[ch]);
        d[ch] = s[x][ch] - ring[ch];
        diff2 += double(d[ch]) * d[ch];
      }
      bg[x] = ring;
      const double k = std::sqrt(diff2) / (std::sqrt(var) + o.noise_level);
      if (k < o.min_contrast) continue;
      for (const double t : o.extensions) {
        uint8_t u[3];
        for (int ch = 0; ch < 3; ++ch) {
          u[ch] = cv::saturate_cast<uint8_t>(ring[ch] + t * d[ch]);
        }
        if ((table.Classify(u[0], u[1], u[2]) & bit) != 0) {
          c[x] = static_cast<float>(k);
          e[x] = static_cast<float>(t);
          break;
        }
      }
    }
  }
  // Local maxima (5x5) of the contrast, strongest first.
  cv::Mat peaks;
  cv::dilate(contrast, peaks, cv::Mat::ones(5, 5, CV_8U));
  struct Peak {
    float k;
    int x, y;
  };
  std::vector<Peak> found;
  for (int y = 0; y < win.height; ++y) {
    const float* c = contrast.ptr<float>(y);
    const float* p = peaks.ptr<float>(y);
    for (int x = 0; x < win.width; ++x) {
      if (c[x] > 0 && c[x] >= p[x]) found.push_back({c[x], x, y});
    }
  }
  std::sort(found.begin(), found.end(), [](const Peak& a, const Peak& b) { return a.k > b.k; });
  for (const Peak& pk : found) {
    if (static_cast<int>(out.size()) >= o.max_spots) break;
    SmallBall s;
    s.contrast = pk.k;
    s.extension = extension.at<float>(pk.y, pk.x);
    // Centre: contrast-weighted mean over 3x3; radius: the ball's share alpha of each pixel
    // within the inner box (the projection of pixel - background on ball - background), summed
    // into an area.
    double wx = 0, wy = 0, w = 0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = pk.x + dx, y = pk.y + dy;
        if (x < 0 || y < 0 || x >= win.width || y >= win.height) continue;
        const double k = contrast.at<float>(y, x);
        wx += k * x, wy += k * y, w += k;
      }
    }
    s.centre_px = Eigen::Vector2d(win.x + wx / w, win.y + wy / w);
    const cv::Vec3f bg = background.at<cv::Vec3f>(pk.y, pk.x);
    const cv::Vec3f centre = spot.at<cv::Vec3f>(pk.y, pk.x);
    const cv::Vec3f ball_minus_bg = s.extension * (centre - bg);
    const double norm2 = ball_minus_bg.dot(ball_minus_bg);
    double area = 0;
    const int h = o.inner_box_px / 2;
    for (int y = std::max(0, pk.y - h); y <= std::min(win.height - 1, pk.y + h); ++y) {
      for (int x = std::max(0, pk.x - h); x <= std::min(win.width - 1, pk.x + h); ++x) {
        const cv::Vec3f px = f.at<cv::Vec3f>(y, x) - bg;
        area += std::clamp(px.dot(ball_minus_bg) / norm2, 0.0, 1.0);
      }
    }
    s.radius_px = std::sqrt(area / M_PI);
    if (s.radius_px > o.max_radius_px) continue;
    out.push_back(s);
  }
  return out;
}

}  // namespace fv::detect
