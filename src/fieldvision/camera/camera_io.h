// Camera files: OpenCV FileStorage YAML as fixed by CONTRACT.md (image_width, image_height,
// camera_matrix, distortion_coefficients, optional rvec/tvec, name, rms_px and notes).
#pragma once

#include <string>

#include "fieldvision/camera/camera.h"

namespace fv::camera {

// Reads and validates a camera file; every problem throws fv::Error naming the file and the key.
Camera ReadCameraYaml(const std::string& path);
// Writes the camera file (to a temporary name first, then renamed, so a failure loses nothing).
void WriteCameraYaml(const Camera& camera, const std::string& path);

}  // namespace fv::camera
