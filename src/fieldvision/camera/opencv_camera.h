// A camera's intrinsics as OpenCV's calib3d and imgproc take them: the 3x3 matrix K and the
// distortion coefficients as one row (five zeros for a camera without distortion).
#pragma once

#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"

namespace fv::camera {

cv::Matx33d IntrinsicMatrix(const Camera& camera);
// A 1xN CV_64F row (its own copy of the coefficients; 1x5 zeros when the camera has none).
cv::Mat DistortionRow(const Camera& camera);

}  // namespace fv::camera
