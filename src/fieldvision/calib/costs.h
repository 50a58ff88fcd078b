// Ceres cost functions of the calibration module, written on the camera's templated model
// (camera/projection.h) so that Ceres differentiates the full OpenCV distortion exactly.
#pragma once

#include <array>

#include <ceres/ceres.h>
#include <Eigen/Core>

#include "fieldvision/camera/projection.h"

namespace fv::calib {

// Reprojection error of a known world point for a camera with fixed intrinsics; parameters
// rvec[3], tvec[3]. Residual in pixels.
struct FixedPointReprojection {
  FixedPointReprojection(const std::array<double, camera::kNumIntrinsics>& intrinsics,
                         const Eigen::Vector2d& uv_px, const Eigen::Vector3d& p_world)
      : intrinsics_(intrinsics), uv_(uv_px), p_(p_world) {}

  template <typename T>
  bool operator()(const T* rvec, const T* tvec, T* residual) const {
    const T p[3] = {T(p_.x()), T(p_.y()), T(p_.z())};
    return Project(rvec, tvec, p, residual);
  }

  template <typename T>
  bool Project(const T* rvec, const T* tvec, const T* p, T* residual) const {
    T intr[camera::kNumIntrinsics];
    for (int i = 0; i < camera::kNumIntrinsics; ++i) intr[i] = T(intrinsics_[i]);
    T uv[2];
    if (!camera::ProjectWorldPoint(intr, rvec, tvec, p, uv)) return false;
    residual[0] = uv[0] - T(uv_.x());
    residual[1] = uv[1] - T(uv_.y());
    return true;
  }

  std::array<double, camera::kNumIntrinsics> intrinsics_;
  Eigen::Vector2d uv_;
  Eigen::Vector3d p_;
};

// The same with the world point as a parameter block (bundle adjustment): rvec, tvec, point.
struct FreePointReprojection {
  FreePointReprojection(const std::array<double, camera::kNumIntrinsics>& intrinsics,
                        const Eigen::Vector2d& uv_px)
      : inner_(intrinsics, uv_px, Eigen::Vector3d::Zero()) {}
  template <typename T>
  bool operator()(const T* rvec, const T* tvec, const T* p, T* residual) const {
    return inner_.Project(rvec, tvec, p, residual);
  }
  FixedPointReprojection inner_;
};

}  // namespace fv::calib
