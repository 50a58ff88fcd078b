// Camera messages for the synchroniser tests: only the camera, frame number and time set. Used
// only by *_test.cc.
#pragma once

#include "fieldvision/pipeline/camera_message.h"

namespace fv::pipeline::test_util {

inline CameraMessage Msg(int camera, long long frame, double time_s) {
  CameraMessage m;
  m.camera = camera;
  m.frame = frame;
  m.time_s = time_s;
  return m;
}

}  // namespace fv::pipeline::test_util
