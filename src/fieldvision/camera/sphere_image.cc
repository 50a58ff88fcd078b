#include "fieldvision/camera/sphere_image.h"

#include <cmath>

namespace fv::camera {

std::optional<double> SphereRadiusPx(const Camera& camera, const Eigen::Vector3d& centre_in_world,
                                     double radius_m) {
  const auto centre = camera.Project(centre_in_world);
  if (!centre) return std::nullopt;
  const Eigen::Vector3d ray = (centre_in_world - camera.CentreInWorld()).normalized();
  const Eigen::Vector3d across = ray.unitOrthogonal();
  double sum = 0;
  for (const Eigen::Vector3d& d : {across, Eigen::Vector3d(ray.cross(across))}) {
    const auto edge = camera.Project(centre_in_world + radius_m * d);
    if (!edge) return std::nullopt;
    sum += (*edge - *centre).norm();
  }
  const double radius_px = 0.5 * sum;
  if (!std::isfinite(radius_px)) return std::nullopt;
  return radius_px;
}

}  // namespace fv::camera
