// Test helpers: camera messages for the synchroniser tests (only the camera, frame number and
// time set) and a posed four-camera rig at the corners of a field. Used only by *_test.cc.
#pragma once

#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/pipeline/camera_message.h"

namespace fv::pipeline::test_util {

inline CameraMessage Msg(int camera, long long frame, double time_s) {
  CameraMessage m;
  m.camera = camera;
  m.frame = frame;
  m.time_s = time_s;
  return m;
}

// Four 1280x960, 70 deg cameras 4.5-6 m up at the corners of a 24 x 18 m area, looking at a
// point 1 m above its centre.
inline std::vector<camera::Camera> CornerRig() {
  std::vector<camera::Camera> cams;
  const Eigen::Vector3d eyes[] = {{-12, -9, 5}, {12, -9, 5.5}, {12, 9, 6}, {-12, 9, 4.5}};
  for (const Eigen::Vector3d& eye : eyes) {
    camera::Camera cam = camera::Camera::FromFov(1280, 960, 70);
    cam.has_pose = true;
    cam.cam_from_world = geometry::Rigid3d::LookAt(eye, Eigen::Vector3d(0, 0, 1));
    cams.push_back(cam);
  }
  return cams;
}

}  // namespace fv::pipeline::test_util
