#include "fieldvision/camera/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <ceres/jet.h>

#include "fieldvision/util/error.h"

namespace fv::camera {
namespace {

bool ValidDistortionSize(size_t n) {
  return n == 0 || n == 4 || n == 5 || n == 8 || n == 12 || n == 14;
}

}  // namespace

Camera Camera::FromFov(int width, int height, double hfov_deg) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 0.5 * width / std::tan(0.5 * hfov_deg * M_PI / 180.0);
  c.cx = 0.5 * (width - 1);
  c.cy = 0.5 * (height - 1);
  return c;
}

void Camera::Check(const std::string& context) const {
  // Limits far beyond any real camera, so that sizes and products of them stay in range.
  constexpr double kMaxPixels = 1e7, kMaxMetres = 1e7, kMaxDistortion = 1e6;
  FV_REQUIRE(width > 0 && height > 0, "{}: image size must be positive (got {}x{})", context, width,
             height);
  FV_REQUIRE(width <= kMaxSide && height <= kMaxSide,
             "{}: image size {}x{} is over the limit of {} pixels a side", context, width, height,
             kMaxSide);
  for (const auto& [name, v] : {std::pair{"fx", fx}, {"fy", fy}, {"cx", cx}, {"cy", cy}}) {
    FV_REQUIRE(std::isfinite(v), "{}: camera_matrix {} is not finite", context, name);
    FV_REQUIRE(std::abs(v) <= kMaxPixels, "{}: camera_matrix {} = {} is out of range (|{}| <= {})",
               context, name, v, name, kMaxPixels);
  }
  FV_REQUIRE(fx > 0 && fy > 0, "{}: camera_matrix focal length must be > 0 (fx={}, fy={})", context,
             fx, fy);
  FV_REQUIRE(ValidDistortionSize(distortion.size()),
             "{}: distortion_coefficients has {} values; OpenCV takes 4, 5, 8, 12 or 14", context,
             distortion.size());
  for (double d : distortion) {
    FV_REQUIRE(std::isfinite(d), "{}: distortion_coefficients contains a non-finite value",
               context);
    FV_REQUIRE(std::abs(d) <= kMaxDistortion, "{}: distortion_coefficients contains {} (|k| <= {})",
               context, d, kMaxDistortion);
  }
  if (has_pose) {
    FV_REQUIRE(cam_from_world.rotation.allFinite() && cam_from_world.translation.allFinite(),
               "{}: rvec/tvec contain a non-finite value", context);
    FV_REQUIRE(cam_from_world.translation.cwiseAbs().maxCoeff() <= kMaxMetres,
               "{}: tvec is out of range (|t| <= {} m)", context, kMaxMetres);
  }
}

std::array<double, kNumIntrinsics> Camera::IntrinsicsBlock() const {
  std::array<double, kNumIntrinsics> b{};
  b[0] = fx;
  b[1] = fy;
  b[2] = cx;
  b[3] = cy;
  for (size_t i = 0; i < distortion.size() && i < kNumDistortion; ++i) b[4 + i] = distortion[i];
  return b;
}

void Camera::SetIntrinsicsBlock(const std::array<double, kNumIntrinsics>& b, int num_distortion) {
  FV_REQUIRE(ValidDistortionSize(num_distortion), "num_distortion {} is not an OpenCV size",
             num_distortion);
  fx = b[0];
  fy = b[1];
  cx = b[2];
  cy = b[3];
  distortion.assign(b.begin() + 4, b.begin() + 4 + num_distortion);
}

Eigen::Vector3d Camera::CentreInWorld() const {
  return -cam_from_world.rotation.transpose() * cam_from_world.translation;
}

std::optional<Eigen::Vector2d> Camera::ProjectFromCamera(const Eigen::Vector3d& p_cam) const {
  const auto intr = IntrinsicsBlock();
  Eigen::Vector2d uv;
  if (!ProjectCameraPoint(intr.data(), p_cam.data(), uv.data())) return std::nullopt;
  return uv;
}

std::optional<Eigen::Vector2d> Camera::Project(const Eigen::Vector3d& p_world) const {
  return ProjectFromCamera(cam_from_world * p_world);
}

namespace {

using Jet2 = ceres::Jet<double, 2>;
using DistortionJets = std::array<Jet2, kNumDistortion>;

// The distortion coefficients `d` (kNumDistortion of them) as constants for dual numbers.
DistortionJets JetsOf(const double* d) {
  DistortionJets dj;
  for (int i = 0; i < kNumDistortion; ++i) dj[i] = Jet2(d[i]);
  return dj;
}

// distort(x) of a normalized point, and its Jacobian in *j (exact, from dual numbers).
Eigen::Vector2d DistortWithJacobian(const DistortionJets& dj, const Eigen::Vector2d& x,
                                    Eigen::Matrix2d* j) {
  Jet2 xd, yd;
  DistortNormalized(dj.data(), Jet2(x.x(), 0), Jet2(x.y(), 1), &xd, &yd);
  *j << xd.v[0], xd.v[1], yd.v[0], yd.v[1];
  return {xd.a, yd.a};
}

// Newton's method on distort(x) = target from `x`; the solution, or nullopt when it does not
// converge or lies where the model folds (the Jacobian's determinant not positive: a second,
// unphysical preimage beyond the radius where a barrel distortion turns back).
std::optional<Eigen::Vector2d> SolveDistortion(const double* d, const Eigen::Vector2d& target,
                                               Eigen::Vector2d x, double fx, double fy) {
  const DistortionJets dj = JetsOf(d);
  Eigen::Matrix2d j;
  for (int iter = 0; iter < 50; ++iter) {
    const Eigen::Vector2d r = DistortWithJacobian(dj, x, &j) - target;
    const double det = j.determinant();
    if (!std::isfinite(det) || det < 1e-12) return std::nullopt;
    if (r.norm() < 1e-14) return x;
    Eigen::Vector2d step = j.inverse() * r;
    // Damp large steps so the iteration stays in the region where the model is monotonic.
    const double max_step = 0.5 * (1.0 + x.norm());
    if (step.norm() > max_step) step *= max_step / step.norm();
    x -= step;
    if (!x.allFinite()) return std::nullopt;
  }
  const Eigen::Vector2d r = DistortWithJacobian(dj, x, &j) - target;
  const double err_px = std::hypot(r.x() * fx, r.y() * fy);
  if (err_px < 1e-6 && j.determinant() > 1e-12) return x;
  return std::nullopt;
}

}  // namespace

std::optional<Eigen::Vector2d> Camera::Undistort(const Eigen::Vector2d& uv) const {
  const auto intr = IntrinsicsBlock();
  const double* d = intr.data() + 4;
  const Eigen::Vector2d target((uv.x() - cx) / fx, (uv.y() - cy) / fy);
  bool any = false;
  for (int i = 0; i < kNumDistortion; ++i) any = any || d[i] != 0.0;
  if (!any) return target;
  if (auto x = SolveDistortion(d, target, target, fx, fy)) return x;
  // Newton from the distorted point failed or reached the folded part: follow the preimage
  // from the image's centre outwards instead (continuation in kSteps steps), which stays on the
  // part of the model connected to the centre; nullopt when the pixel lies beyond the fold.
  constexpr int kSteps = 16;
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  for (int k = 1; k <= kSteps; ++k) {
    const auto next = SolveDistortion(d, target * (double(k) / kSteps), x, fx, fy);
    if (!next) return std::nullopt;
    x = *next;
  }
  return x;
}

double Camera::DistortionMinScale(const Eigen::Vector2d& xn) const {
  const auto intr = IntrinsicsBlock();
  Eigen::Matrix2d j;
  DistortWithJacobian(JetsOf(intr.data() + 4), xn, &j);
  if (!j.allFinite() || j.determinant() <= 0) return std::numeric_limits<double>::quiet_NaN();
  // A 2x2 matrix's singular values: s_max^2 = (a + sqrt(a^2 - 4 det^2)) / 2 with a its squared
  // Frobenius norm, and s_min = det / s_max (no cancellation).
  const double a = j.squaredNorm(), det = j.determinant();
  const double s_max = std::sqrt(0.5 * (a + std::sqrt(std::max(a * a - 4 * det * det, 0.0))));
  return det / s_max;
}

std::optional<geometry::Ray3d> Camera::RayFromPixel(const Eigen::Vector2d& uv) const {
  const auto xn = Undistort(uv);
  if (!xn) return std::nullopt;
  const Eigen::Vector3d dir_cam = Eigen::Vector3d(xn->x(), xn->y(), 1.0).normalized();
  return geometry::Ray3d{CentreInWorld(), cam_from_world.rotation.transpose() * dir_cam};
}

double Camera::PixelFootprintM(const Eigen::Vector3d& p_world) const {
  const double depth = (cam_from_world * p_world).z();
  return std::abs(depth) / std::sqrt(fx * fy);
}

bool Camera::InImage(const Eigen::Vector2d& uv, double margin_px) const {
  return uv.x() >= -0.5 + margin_px && uv.y() >= -0.5 + margin_px &&
         uv.x() < width - 0.5 - margin_px && uv.y() < height - 0.5 - margin_px;
}

}  // namespace fv::camera
