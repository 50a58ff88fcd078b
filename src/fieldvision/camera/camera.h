// A calibrated camera: size, intrinsics, OpenCV distortion and the pose cam_from_world
// (x_cam = R x_world + t). Projection, back-projection to world rays, pixel footprint.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "fieldvision/camera/projection.h"
#include "fieldvision/geometry/rigid.h"

namespace fv::camera {

struct Camera {
  std::string name;
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  // 0, 4, 5, 8, 12 or 14 coefficients in OpenCV order.
  std::vector<double> distortion;
  bool has_pose = false;
  geometry::Rigid3d cam_from_world;
  // Optional metadata written to and read from the camera file.
  std::optional<double> rms_px;
  std::map<std::string, std::string> notes;

  // A camera with given size and horizontal field of view, principal point at the centre.
  static Camera FromFov(int width, int height, double hfov_deg);

  // Throws fv::Error naming `context` and the bad member (size, focal, NaN, distortion size).
  void Check(const std::string& context = "camera") const;
  // The largest image side Check accepts: far beyond any real camera, so that sizes and products
  // of them stay in range.
  static constexpr int kMaxSide = 65536;

  // fx, fy, cx, cy, d[14]: the parameter block of projection.h.
  std::array<double, kNumIntrinsics> IntrinsicsBlock() const;
  void SetIntrinsicsBlock(const std::array<double, kNumIntrinsics>& block, int num_distortion);

  Eigen::Vector3d CentreInWorld() const;
  // The optical axis (the camera's z) as a unit direction in the world.
  Eigen::Vector3d AxisInWorld() const { return cam_from_world.rotation.row(2).transpose(); }
  geometry::Rigid3d world_from_cam() const { return cam_from_world.Inverse(); }

  // World point -> pixel; nullopt when the point is behind the camera. Not clipped to the image.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& p_world) const;
  std::optional<Eigen::Vector2d> ProjectFromCamera(const Eigen::Vector3d& p_cam) const;
  // Pixel -> normalized undistorted point (x/z, y/z); nullopt if the inversion does not converge.
  std::optional<Eigen::Vector2d> Undistort(const Eigen::Vector2d& uv) const;
  // Pixel -> unit ray in the world from the camera centre.
  std::optional<geometry::Ray3d> RayFromPixel(const Eigen::Vector2d& uv) const;
  // Metres on a plane facing the camera covered by one pixel at the depth of `p_world`.
  double PixelFootprintM(const Eigen::Vector3d& p_world) const;
  // The lens distortion's smallest local magnification at normalized point `xn` (x/z, y/z): the
  // smaller singular value of its Jacobian, 1 without distortion (a barrel lens shrinks things
  // near the border, most along the radius). Not finite where the model folds.
  double DistortionMinScale(const Eigen::Vector2d& xn) const;
  // Inside the image, OpenCV pixel centres: [-0.5, w - 0.5) x [-0.5, h - 0.5), shrunk by margin.
  bool InImage(const Eigen::Vector2d& uv, double margin_px = 0.0) const;
};

}  // namespace fv::camera
