// The image size of a sphere (a ball) seen by a camera: the mean distance from the projection of
// its centre to those of two points one radius away across the viewing ray, so that lens
// distortion (a fisheye's squeeze near the border) is included, as the detector, the fusion and
// the fusion's hints need it.
#pragma once

#include <optional>

#include <Eigen/Core>

#include "fieldvision/camera/camera.h"

namespace fv::camera {

// The image radius in pixels of a sphere of `radius_m` centred at `centre_in_world`; nullopt when
// a point does not project (behind the camera) or the result is not finite.
std::optional<double> SphereRadiusPx(const Camera& camera, const Eigen::Vector3d& centre_in_world,
                                     double radius_m);

}  // namespace fv::camera
