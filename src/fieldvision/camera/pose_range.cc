#include "fieldvision/camera/pose_range.h"

#include "fieldvision/util/error.h"

namespace fv::camera {

void CheckCameraNearOrigin(const Camera& camera, const std::string& what) {
  if (!camera.has_pose) return;
  const double d = camera.CentreInWorld().norm();
  FV_REQUIRE(d <= kMaxCameraDistanceM,
             "{}: camera '{}' stands {:.3g} m from the world origin (at most {:.0f} m): are its "
             "translations (or the points it was placed with) in metres?",
             what, camera.name, d, kMaxCameraDistanceM);
}

}  // namespace fv::camera
