// Helpers shared by the track tests (header only, not part of the library): a posed camera beside
// a field and the image box of a person standing on it.
#pragma once

#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"

namespace fv::track::test_util {

// 1280x720, 70 degrees wide, 14 m from the field's centre line and 6 m up, looking at the centre.
inline camera::Camera SideCamera() {
  camera::Camera c = camera::Camera::FromFov(1280, 720, 70);
  c.cam_from_world = geometry::Rigid3d::LookAt({0, -14, 6}, {0, 0, 0});
  c.has_pose = true;
  return c;
}

// The image box of a 1.8 m person standing at (x, y), 0.4 of its height wide, with its lowest
// hidden_m not in the box (legs hidden) and its bottom moved down by noise_px.
inline cv::Rect2d PersonBox(const camera::Camera& cam, double x, double y, double hidden_m = 0.0,
                            double noise_px = 0.0) {
  const auto foot = cam.Project({x, y, hidden_m});
  const auto head = cam.Project({x, y, 1.8});
  const double h = foot->y() - head->y();
  return {foot->x() - 0.2 * h, head->y(), 0.4 * h, h + noise_px};
}

}  // namespace fv::track::test_util
