// Helpers shared by the track tests (header only, not part of the library): a posed camera beside
// a field, the image box of a person standing on it and the distance between two views.
#pragma once

#include <algorithm>
#include <cmath>

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

// The largest distance between where homographies a and b take a grid of points: x from x0 to
// x1 and y from y0 to y1 in `steps` steps each.
inline double ViewError(const cv::Matx33d& a, const cv::Matx33d& b, double x0, double x1, double y0,
                        double y1, int steps) {
  double worst = 0;
  for (int i = 0; i <= steps; ++i) {
    for (int j = 0; j <= steps; ++j) {
      const double x = x0 + (x1 - x0) * i / steps, y = y0 + (y1 - y0) * j / steps;
      const cv::Vec3d qa = a * cv::Vec3d(x, y, 1), qb = b * cv::Vec3d(x, y, 1);
      worst =
          std::max(worst, std::hypot(qa[0] / qa[2] - qb[0] / qb[2], qa[1] / qa[2] - qb[1] / qb[2]));
    }
  }
  return worst;
}

}  // namespace fv::track::test_util
