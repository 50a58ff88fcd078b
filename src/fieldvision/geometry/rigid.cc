#include "fieldvision/geometry/rigid.h"

#include <cmath>

#include <ceres/rotation.h>

namespace fv::geometry {

Eigen::Matrix3d RotationFromRvec(const Eigen::Vector3d& rvec) {
  Eigen::Matrix3d r;
  ceres::AngleAxisToRotationMatrix(rvec.data(), ceres::ColumnMajorAdapter3x3(r.data()));
  return r;
}

Eigen::Vector3d RvecFromRotation(const Eigen::Matrix3d& rotation) {
  Eigen::Vector3d rvec;
  ceres::RotationMatrixToAngleAxis(ceres::ColumnMajorAdapter3x3(rotation.data()), rvec.data());
  return rvec;
}

double RotationAngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return RvecFromRotation(a.transpose() * b).norm();
}

Rigid3d Rigid3d::FromRvecTvec(const Eigen::Vector3d& rvec, const Eigen::Vector3d& tvec) {
  return {RotationFromRvec(rvec), tvec};
}

Eigen::Vector3d Rigid3d::Rvec() const { return RvecFromRotation(rotation); }

Rigid3d Rigid3d::LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d up(0, 0, 1);
  if (std::abs(z.dot(up)) > 0.999) up = Eigen::Vector3d(0, 1, 0);
  const Eigen::Vector3d x = z.cross(up).normalized();  // image right
  const Eigen::Vector3d y = z.cross(x);                // image down
  Eigen::Matrix3d world_from_cam_rot;
  world_from_cam_rot.col(0) = x;
  world_from_cam_rot.col(1) = y;
  world_from_cam_rot.col(2) = z;
  Rigid3d cam_from_world;
  cam_from_world.rotation = world_from_cam_rot.transpose();
  cam_from_world.translation = -cam_from_world.rotation * eye;
  return cam_from_world;
}

std::optional<Eigen::Vector3d> IntersectHorizontalPlane(const Ray3d& ray, double height) {
  if (std::abs(ray.direction.z()) < 1e-12) return std::nullopt;
  const double s = (height - ray.origin.z()) / ray.direction.z();
  if (s <= 0) return std::nullopt;
  return ray.At(s);
}

}  // namespace fv::geometry
