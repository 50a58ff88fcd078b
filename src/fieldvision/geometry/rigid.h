// Rigid transforms and rays. A pose `cam_from_world` maps world points into the camera frame:
// x_cam = R * x_world + t, the convention of OpenCV's solvePnP (rvec = angle-axis of R).
#pragma once

#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace fv::geometry {

struct Rigid3d {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  static Rigid3d FromRvecTvec(const Eigen::Vector3d& rvec, const Eigen::Vector3d& tvec);
  // A camera at `eye` looking at `target`, image y down and the image's "up" towards +z.
  static Rigid3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target);
  Eigen::Vector3d Rvec() const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return rotation * p + translation; }
  Rigid3d operator*(const Rigid3d& o) const {
    return {rotation * o.rotation, rotation * o.translation + translation};
  }
  Rigid3d Inverse() const { return {rotation.transpose(), -rotation.transpose() * translation}; }
};

// Angle-axis vector <-> rotation matrix (Rodrigues).
Eigen::Matrix3d RotationFromRvec(const Eigen::Vector3d& rvec);
Eigen::Vector3d RvecFromRotation(const Eigen::Matrix3d& rotation);
// Angle between two rotations in radians.
double RotationAngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

struct Ray3d {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;  // unit length
  Eigen::Vector3d At(double s) const { return origin + s * direction; }
};

// Where the ray meets the horizontal plane z = height (only in front of the origin).
std::optional<Eigen::Vector3d> IntersectHorizontalPlane(const Ray3d& ray, double height);

}  // namespace fv::geometry
