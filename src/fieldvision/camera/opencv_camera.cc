#include "fieldvision/camera/opencv_camera.h"

namespace fv::camera {

cv::Matx33d IntrinsicMatrix(const Camera& camera) {
  return {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
}

cv::Mat DistortionRow(const Camera& camera) {
  if (camera.distortion.empty()) return cv::Mat::zeros(1, 5, CV_64F);
  return cv::Mat(camera.distortion, true).reshape(1, 1);
}

}  // namespace fv::camera
