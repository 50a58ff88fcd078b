// Camera files: OpenCV FileStorage YAML as fixed by CONTRACT.md (image_width, image_height,
// camera_matrix, distortion_coefficients, optional rvec/tvec, name, rms_px and notes).
#pragma once

#include <string>

#include <opencv2/core/persistence.hpp>

#include "fieldvision/camera/camera.h"

namespace fv::camera {

// Reads and validates a camera file; every problem throws fv::Error naming the file and the key.
Camera ReadCameraYaml(const std::string& path);
// Throws fv::Error naming `what`, the file and the line when an OpenCV YAML file has a line that
// starts a document ("---") with more on it: OpenCV 4.6's parser never returns on some of those
// ("--- A: 1" then a line "--m"; found by fuzz/camera_yaml_fuzz), and OpenCV writes "---" alone.
// Files over 64 MB are refused (OpenCV reads them whole).
void CheckOpenCvYamlText(const std::string& path, const std::string& what);
// Writes the camera file (to a temporary name first, then renamed, so a failure loses nothing).
void WriteCameraYaml(const Camera& camera, const std::string& path);
// An OpenCV YAML writer in memory: plain YAML whatever the file's name (a name ending in .gz or
// .xml, or a temporary name, would choose another format). SaveYaml writes what it holds as the
// whole of `file` (a temporary file, util::AtomicWrite); throws "cannot write WHAT 'path'".
cv::FileStorage NewYamlWriter();
void SaveYaml(cv::FileStorage& fs, const std::string& file, const std::string& path,
              const std::string& what);

}  // namespace fv::camera
