// N views, linear: DLT on undistorted normalized points, each row weighted by 1 / sigma
// (Hartley & Zisserman, "Multiple View Geometry", 2nd ed., sec. 12.2).
#include "fieldvision/recon/triangulation.h"

#include <cmath>

#include <Eigen/Dense>

#include "fieldvision/recon/triangulation_internal.h"
#include "fieldvision/util/error.h"

namespace fv::recon {

using detail::CheckCamera;
using detail::CheckObservation;

std::optional<Eigen::Vector3d> TriangulateLinear(const std::vector<camera::Camera>& cameras,
                                                 const std::vector<View>& views) {
  if (views.size() < 2) return std::nullopt;
  // Centre the world on the mean camera centre for conditioning.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const View& v : views) {
    CheckCamera(cameras, v.camera);
    centre += cameras[v.camera].CentreInWorld();
  }
  centre /= static_cast<double>(views.size());
  Eigen::MatrixXd a(2 * views.size(), 4);
  for (size_t i = 0; i < views.size(); ++i) {
    const camera::Camera& cam = cameras[views[i].camera];
    CheckObservation(views[i].observation, "triangulation");
    const auto xn = cam.Undistort(views[i].observation.centre_px);
    if (!xn) return std::nullopt;
    // P = [R | t + R c] maps the centred point to the camera.
    Eigen::Matrix<double, 3, 4> p;
    p.leftCols<3>() = cam.cam_from_world.rotation;
    p.col(3) = cam.cam_from_world.translation + cam.cam_from_world.rotation * centre;
    // Weight each view by 1 / sigma in normalized units and normalise the rows' scale.
    const double w = std::sqrt(cam.fx * cam.fy) / views[i].observation.sigma_px;
    Eigen::RowVector4d r0 = xn->x() * p.row(2) - p.row(0);
    Eigen::RowVector4d r1 = xn->y() * p.row(2) - p.row(1);
    const double depth_scale = p.row(2).head<3>().norm();  // unit: rows are in metres
    a.row(2 * i) = w * r0 / depth_scale;
    a.row(2 * i + 1) = w * r1 / depth_scale;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d x = svd.matrixV().col(3);
  if (!x.allFinite() || std::abs(x(3)) < 1e-12 * x.head<3>().norm()) return std::nullopt;
  const Eigen::Vector3d p = x.head<3>() / x(3) + centre;
  if (!p.allFinite()) return std::nullopt;
  return p;
}

}  // namespace fv::recon
