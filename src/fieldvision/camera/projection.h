// The pinhole camera with OpenCV's full distortion model (k1..k6 rational radial, p1 p2
// tangential, s1..s4 thin prism, tauX tauY tilted sensor), templated on the scalar so that Ceres
// can differentiate it. Same formulas as cv::projectPoints (OpenCV calib3d docs, "Camera
// Calibration and 3D Reconstruction"); distortion vectors shorter than 14 are zero-padded.
#pragma once

#include <cmath>

#include <ceres/rotation.h>

namespace fv::camera {

constexpr int kNumDistortion = 14;
// Intrinsic parameter block: fx, fy, cx, cy, then the 14 distortion coefficients in OpenCV order
// k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tauX tauY.
constexpr int kNumIntrinsics = 4 + kNumDistortion;

// Normalized image point (x, y) = (X/Z, Y/Z) -> distorted normalized point, tilt included.
template <typename T>
void DistortNormalized(const T* d, const T& x, const T& y, T* xd, T* yd) {
  const T r2 = x * x + y * y;
  const T r4 = r2 * r2;
  const T r6 = r4 * r2;
  const T radial =
      (T(1) + d[0] * r2 + d[1] * r4 + d[4] * r6) / (T(1) + d[5] * r2 + d[6] * r4 + d[7] * r6);
  const T a1 = T(2) * x * y;
  const T a2 = r2 + T(2) * x * x;
  const T a3 = r2 + T(2) * y * y;
  T u = x * radial + d[2] * a1 + d[3] * a2 + d[8] * r2 + d[9] * r4;
  T v = y * radial + d[2] * a3 + d[3] * a1 + d[10] * r2 + d[11] * r4;
  const T& tau_x = d[12];
  const T& tau_y = d[13];
  if (tau_x != T(0) || tau_y != T(0)) {
    // OpenCV's computeTiltProjectionMatrix: R = Ry(tauY) * Rx(tauX), then a projection onto z.
    using std::cos;
    using std::sin;
    const T cx = cos(tau_x), sx = sin(tau_x), cy = cos(tau_y), sy = sin(tau_y);
    // R = [cy, sx*sy, -sy*cx; 0, cx, sx; sy, -cy*sx, cy*cx]
    const T& r00 = cy;
    const T r01 = sx * sy, r02 = -sy * cx;
    const T r10 = T(0);
    const T& r11 = cx;
    const T& r12 = sx;
    const T& r20 = sy;
    const T r21 = -cy * sx, r22 = cy * cx;
    // Tilt = [r22 0 -r02; 0 r22 -r12; 0 0 1] * R
    const T t0 =
        (r22 * r00 - r02 * r20) * u + (r22 * r01 - r02 * r21) * v + (r22 * r02 - r02 * r22);
    const T t1 =
        (r22 * r10 - r12 * r20) * u + (r22 * r11 - r12 * r21) * v + (r22 * r12 - r12 * r22);
    const T t2 = r20 * u + r21 * v + r22;
    u = t0 / t2;
    v = t1 / t2;
  }
  *xd = u;
  *yd = v;
}

// Point in the camera frame -> pixel. Returns false when the point is not in front (Z <= 0).
template <typename T>
bool ProjectCameraPoint(const T* intrinsics, const T* p_cam, T* uv) {
  if (!(p_cam[2] > T(0))) return false;
  const T x = p_cam[0] / p_cam[2];
  const T y = p_cam[1] / p_cam[2];
  T xd, yd;
  DistortNormalized(intrinsics + 4, x, y, &xd, &yd);
  uv[0] = intrinsics[0] * xd + intrinsics[2];
  uv[1] = intrinsics[1] * yd + intrinsics[3];
  return true;
}

// World point -> pixel through the pose (rvec = angle-axis of R, x_cam = R x_world + t).
template <typename T>
bool ProjectWorldPoint(const T* intrinsics, const T* rvec, const T* tvec, const T* p_world, T* uv) {
  T p_cam[3];
  ceres::AngleAxisRotatePoint(rvec, p_world, p_cam);
  p_cam[0] += tvec[0];
  p_cam[1] += tvec[1];
  p_cam[2] += tvec[2];
  return ProjectCameraPoint(intrinsics, p_cam, uv);
}

}  // namespace fv::camera
