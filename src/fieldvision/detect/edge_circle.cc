#include "fieldvision/detect/edge_circle.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "fieldvision/detect/ball_fit.h"
#include "fieldvision/detect/bilinear.h"
#include "fieldvision/util/error.h"

namespace fv::detect {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kStepPx = 0.25;  // profile sampling along a ray

// The strongest colour step along the ray c + t u, 0.6 r <= t <= 1.45 r (the step across 1 px,
// the peak refined by a parabola), or nullopt when it is below min_step or the ray leaves the
// image.
std::optional<Vector2d> RayEdge(const cv::Mat& img, Sampler* sample, const Vector2d& c,
                                const Vector2d& u, double r, double min_step) {
  const double t0 = 0.6 * r - 0.5, t1 = 1.45 * r + 0.5;
  const int n = static_cast<int>(std::floor((t1 - t0) / kStepPx)) + 1;
  // The profile lies inside the image when both its ends do (Sampler::Inside).
  if (!InsideForSampling(img, c + t0 * u) ||
      !InsideForSampling(img, c + (t0 + (n - 1) * kStepPx) * u)) {
    return std::nullopt;
  }
  std::vector<Vector3d> profile(n);
  for (int i = 0; i < n; ++i) {
    const Vector2d p = c + (t0 + i * kStepPx) * u;
    sample->Inside(p.x(), p.y(), &profile[i]);
  }
  constexpr int kHalf = 2;  // samples in half a pixel
  int best = -1;
  double best_step = 0.0;
  std::vector<double> step(n, 0.0);
  for (int i = kHalf; i + kHalf < n; ++i) {
    step[i] = (profile[i + kHalf] - profile[i - kHalf]).norm();
    if (step[i] > best_step) {
      best_step = step[i];
      best = i;
    }
  }
  if (best < 0 || best_step < min_step) return std::nullopt;
  double offset = 0.0;
  if (best > kHalf && best + kHalf + 1 < n) {
    const double l = step[best - 1], m = step[best], rr = step[best + 1];
    const double den = l - 2 * m + rr;
    if (den < 0) offset = std::clamp(0.5 * (l - rr) / den, -0.5, 0.5);
  }
  return c + (t0 + (best + offset) * kStepPx) * u;
}

// Whether a circle agrees with the expected one.
bool Agrees(const Vector2d& centre, double radius, const Vector2d& want_centre, double want_radius,
            const EdgeCircleOptions& o) {
  return std::abs(radius - want_radius) <= o.max_radius_change * want_radius + 0.5 &&
         (centre - want_centre).norm() <= o.max_shift_radii * want_radius + 1.0;
}

// RANSAC over triples (a fixed sequence of draws) for the circle that agrees with the expected
// one and has the most points within thr; false when no triple agrees.
bool PriorRansac(const std::vector<Vector2d>& pts, const Vector2d& want_centre, double want_radius,
                 double thr, const EdgeCircleOptions& o, Vector2d* centre, double* radius) {
  const int n = static_cast<int>(pts.size());
  uint64_t state = 0x9e3779b97f4a7c15ull;
  const auto draw = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<int>((state >> 33) % static_cast<uint64_t>(n));
  };
  int best_count = 0;
  for (int it = 0; it < o.ransac_iterations; ++it) {
    const int i = draw(), j = draw(), k = draw();
    if (i == j || j == k || i == k) continue;
    Vector2d c;
    double r = 0;
    if (!CircleFrom3(pts[i], pts[j], pts[k], &c, &r) ||
        !Agrees(c, r, want_centre, want_radius, o)) {
      continue;
    }
    int count = 0;
    for (const Vector2d& p : pts) count += std::abs((p - c).norm() - r) <= thr;
    if (count > best_count) {
      best_count = count;
      *centre = c;
      *radius = r;
    }
  }
  return best_count >= 3;
}

}  // namespace

void EdgeCircleOptions::Check() const {
  CheckPositive(min_step, "EdgeCircleOptions.min_step");
  CheckInRange(max_radius_change, 0.0, 1.0, "EdgeCircleOptions.max_radius_change");
  CheckInRange(max_shift_radii, 0.0, 10.0, "EdgeCircleOptions.max_shift_radii");
  CheckPositive(inlier_px, "EdgeCircleOptions.inlier_px");
  FV_REQUIRE(ransac_iterations >= 1, "EdgeCircleOptions.ransac_iterations must be >= 1 (got {})",
             ransac_iterations);
}

EdgeCircle FitEdgeCircle(const cv::Mat& bgr, const Vector2d& centre_px, double radius_px,
                         const EdgeCircleOptions& o) {
  o.Check();
  FV_REQUIRE(bgr.type() == CV_8UC3, "edge circle: the image must be 8-bit BGR (got type {})",
             bgr.type());
  EdgeCircle out;
  if (!centre_px.allFinite() || !(radius_px >= 1.0)) return out;
  const int rays = std::clamp(static_cast<int>(2 * M_PI * radius_px / 1.5), 16, 96);
  std::vector<Vector2d> pts;
  pts.reserve(rays);
  Sampler sample(bgr);
  for (int k = 0; k < rays; ++k) {
    const double th = 2 * M_PI * k / rays;
    const auto p = RayEdge(bgr, &sample, centre_px, Vector2d(std::cos(th), std::sin(th)), radius_px,
                           o.min_step);
    if (p) pts.push_back(*p);
  }
  if (static_cast<int>(pts.size()) < rays / 2) return out;
  const double thr = o.inlier_px + 0.03 * radius_px;
  Vector2d c;
  double r = 0;
  if (!PriorRansac(pts, centre_px, radius_px, thr, o, &c, &r)) return out;
  std::vector<char> inlier;
  if (!FitCircle(pts, thr, &c, &r, &inlier) || !Agrees(c, r, centre_px, radius_px, o)) return out;
  double sum2 = 0;
  int count = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!inlier[i]) continue;
    const double d = (pts[i] - c).norm() - r;
    sum2 += d * d;
    ++count;
  }
  if (count < 3) return out;
  out.ok = true;
  out.centre_px = c;
  out.radius_px = r;
  out.rms_px = std::sqrt(sum2 / count);
  out.inlier_fraction = static_cast<double>(count) / rays;
  // A circle's centre from n points spread around it: each axis ~ rms * sqrt(2 / n).
  out.sigma_px = std::max(out.rms_px, 0.1) * std::sqrt(2.0 / count);
  return out;
}

}  // namespace fv::detect
