#include "fieldvision/track/ground_smoother.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "fieldvision/geometry/rigid.h"
#include "fieldvision/util/error.h"

namespace fv::track {
namespace {

using Mat4 = Eigen::Matrix4d;
using Vec4 = Eigen::Vector4d;

// The ground point under pixel (u, v), or false.
bool Ground(const camera::Camera& camera, double u, double v, Eigen::Vector2d* g) {
  const auto ray = camera.RayFromPixel({u, v});
  if (!ray) return false;
  const auto p = geometry::IntersectHorizontalPlane(*ray, 0.0);
  if (!p) return false;
  *g = p->head<2>();
  return true;
}

// Measurement covariance of the foot point of `box`: the footprint of +-sigma_px vertically
// (along the image column) plus the same horizontally, with a floor.
Eigen::Matrix2d FootCovariance(const camera::Camera& camera, const cv::Rect2d& box,
                               const GroundSmoothOptions& o) {
  const double u = box.x + 0.5 * box.width, v = box.y + box.height;
  const double s_px = std::max(o.foot_sigma_frac * box.height, 0.5);
  Eigen::Matrix2d r = o.min_sigma_m * o.min_sigma_m * Eigen::Matrix2d::Identity();
  Eigen::Vector2d a, b, c, d;
  if (Ground(camera, u, v - s_px, &a) && Ground(camera, u, v + s_px, &b)) {
    const Eigen::Vector2d e = 0.5 * (b - a);
    r += e * e.transpose();
  } else {
    r += Eigen::Matrix2d::Identity();  // near the horizon: a weak measurement
  }
  if (Ground(camera, u - s_px, v, &c) && Ground(camera, u + s_px, v, &d)) {
    const Eigen::Vector2d e = 0.5 * (d - c);
    r += e * e.transpose();
  }
  return r;
}

}  // namespace

void GroundSmoothOptions::Check() const {
  FV_REQUIRE(std::isfinite(accel_sigma_mps2) && accel_sigma_mps2 > 0,
             "GroundSmoothOptions.accel_sigma_mps2 must be > 0 (got {})", accel_sigma_mps2);
  FV_REQUIRE(std::isfinite(foot_sigma_frac) && foot_sigma_frac > 0,
             "GroundSmoothOptions.foot_sigma_frac must be > 0 (got {})", foot_sigma_frac);
  FV_REQUIRE(std::isfinite(min_sigma_m) && min_sigma_m > 0,
             "GroundSmoothOptions.min_sigma_m must be > 0 (got {})", min_sigma_m);
}

std::string GroundSmoothResult::Summary() const {
  return fmt::format(
      "{} tracks smoothed on the ground ({} measurements, {} filled), mean shift "
      "{:.3f} m",
      tracks, measurements, filled, mean_shift_m);
}

GroundSmoothResult SmoothGroundTracks(std::vector<TrackRow>& rows,
                                      const std::vector<bool>& measured,
                                      const camera::Camera& camera, double fps,
                                      const GroundSmoothOptions& o) {
  o.Check();
  FV_REQUIRE(std::isfinite(fps) && fps > 0, "SmoothGroundTracks: fps must be > 0 (got {})", fps);
  FV_REQUIRE(measured.empty() || measured.size() == rows.size(),
             "SmoothGroundTracks: {} measured flags for {} rows", measured.size(), rows.size());
  GroundSmoothResult result;
  if (!o.enabled || !camera.has_pose) return result;
  std::map<int, std::vector<size_t>> by_id;
  for (size_t i = 0; i < rows.size(); ++i) by_id[rows[i].id].push_back(i);
  double shift_sum = 0;
  for (auto& [id, idx] : by_id) {
    std::sort(idx.begin(), idx.end(),
              [&](size_t a, size_t b) { return rows[a].frame < rows[b].frame; });
    const size_t n = idx.size();
    std::vector<Vec4> x_f(n), x_p(n);
    std::vector<Mat4> p_f(n), p_p(n), f_of(n);
    bool started = false;
    int used = 0;
    for (size_t k = 0; k < n; ++k) {
      const TrackRow& r = rows[idx[k]];
      const bool is_meas = r.x_m && r.y_m && (measured.empty() || measured[idx[k]]);
      const double dt = k == 0 ? 0.0 : std::max(1, r.frame - rows[idx[k - 1]].frame) / fps;
      Mat4 f = Mat4::Identity();
      f(0, 2) = f(1, 3) = dt;
      f_of[k] = f;
      if (!started) {
        if (!is_meas) {
          x_p[k] = x_f[k] = Vec4::Zero();
          p_p[k] = p_f[k] = 1e6 * Mat4::Identity();
          continue;
        }
        started = true;
        x_f[k] << *r.x_m, *r.y_m, 0, 0;
        p_f[k] = Mat4::Zero();
        p_f[k].topLeftCorner<2, 2>() = FootCovariance(camera, r.box, o);
        p_f[k](2, 2) = p_f[k](3, 3) = 4.0;  // up to a sprint, m/s
        x_p[k] = x_f[k];
        p_p[k] = p_f[k];
        ++used;
        continue;
      }
      // Predict (white-noise acceleration).
      const double q = o.accel_sigma_mps2 * o.accel_sigma_mps2;
      Mat4 qm = Mat4::Zero();
      const double dt2 = dt * dt, dt3 = dt2 * dt, dt4 = dt3 * dt;
      for (int a = 0; a < 2; ++a) {
        qm(a, a) = q * dt4 / 4;
        qm(a, a + 2) = qm(a + 2, a) = q * dt3 / 2;
        qm(a + 2, a + 2) = q * dt2;
      }
      x_p[k] = f * x_f[k - 1];
      p_p[k] = f * p_f[k - 1] * f.transpose() + qm;
      x_f[k] = x_p[k];
      p_f[k] = p_p[k];
      if (is_meas) {
        const Eigen::Matrix2d rm = FootCovariance(camera, r.box, o);
        const Eigen::Vector2d z(*r.x_m, *r.y_m);
        const Eigen::Matrix2d s = p_p[k].topLeftCorner<2, 2>() + rm;
        const Eigen::Matrix<double, 4, 2> gain = p_p[k].leftCols<2>() * s.inverse();
        x_f[k] = x_p[k] + gain * (z - x_p[k].head<2>());
        p_f[k] = (Mat4::Identity() - gain * Eigen::Matrix<double, 2, 4>::Identity()) * p_p[k];
        ++used;
      }
    }
    if (used == 0) continue;
    // Backward pass.
    std::vector<Vec4> x_s = x_f;
    for (size_t k = n - 1; k-- > 0;) {
      if (p_f[k](0, 0) >= 1e5) continue;  // before the first measurement
      const Mat4 c = p_f[k] * f_of[k + 1].transpose() * p_p[k + 1].inverse();
      x_s[k] = x_f[k] + c * (x_s[k + 1] - x_p[k + 1]);
    }
    ++result.tracks;
    for (size_t k = 0; k < n; ++k) {
      if (p_f[k](0, 0) >= 1e5) continue;
      TrackRow& r = rows[idx[k]];
      const bool is_meas = r.x_m && r.y_m && (measured.empty() || measured[idx[k]]);
      if (is_meas) {
        shift_sum += std::hypot(*r.x_m - x_s[k](0), *r.y_m - x_s[k](1));
        ++result.measurements;
      } else {
        ++result.filled;
      }
      r.x_m = x_s[k](0);
      r.y_m = x_s[k](1);
    }
  }
  result.mean_shift_m = result.measurements ? shift_sum / result.measurements : 0.0;
  return result;
}

}  // namespace fv::track
