// One camera, the ball on the ground: the ray meets the plane z = ball radius, then x, y are
// refined on the reprojection error.
#include "fieldvision/recon/triangulation.h"

#include "fieldvision/recon/triangulation_internal.h"
#include "fieldvision/util/error.h"

namespace fv::recon {

using detail::CheckObservation;
using detail::Depth;
using detail::Refine;

TriangulationResult LocateOnGround(const camera::Camera& camera, int camera_index,
                                   const BallObservation& observation,
                                   const TriangulationOptions& options) {
  options.Check();
  FV_REQUIRE(camera.has_pose, "LocateOnGround: camera '{}' has no pose", camera.name);
  CheckObservation(observation, "LocateOnGround");
  TriangulationResult result;
  const auto ray = camera.RayFromPixel(observation.centre_px);
  if (!ray) {
    result.status = TriangulationStatus::kDegenerate;
    return result;
  }
  const auto hit = geometry::IntersectHorizontalPlane(*ray, options.ball_radius_m);
  if (!hit || !(Depth(camera, *hit) > options.min_depth_m)) {
    result.status = TriangulationStatus::kBehindCamera;
    return result;
  }
  Eigen::Vector3d p(hit->x(), hit->y(), options.ball_radius_m);
  std::vector<camera::Camera> cams = {camera};
  std::vector<View> views = {{0, observation}};
  Refine(cams, views, {0}, true, options, &p, &result);
  for (auto& v : result.views) v.camera = camera_index;
  result.on_ground = true;
  result.status = Depth(camera, p) > options.min_depth_m ? TriangulationStatus::kOk
                                                         : TriangulationStatus::kBehindCamera;
  return result;
}

}  // namespace fv::recon
