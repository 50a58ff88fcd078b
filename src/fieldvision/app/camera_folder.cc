#include "fieldvision/app/camera_folder.h"

#include <algorithm>
#include <filesystem>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/util/error.h"

namespace fv::app {

camera::Camera ReadNamedCamera(const std::string& path) {
  camera::Camera c = camera::ReadCameraYaml(path);
  if (c.name.empty()) c.name = std::filesystem::path(path).stem().string();
  return c;
}

std::vector<std::string> CameraFilesIn(const std::string& dir) {
  namespace fs = std::filesystem;
  FV_REQUIRE(fs::is_directory(dir), "rig '{}' is not a folder (give the folder of calibrate multi)",
             dir);
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".yaml" || ext == ".yml")) {
      files.push_back(e.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<camera::Camera> ReadCameraFolder(const std::string& dir, bool require_pose) {
  std::vector<camera::Camera> cams;
  for (const auto& f : CameraFilesIn(dir)) {
    cams.push_back(ReadNamedCamera(f));
    FV_REQUIRE(!require_pose || cams.back().has_pose,
               "rig '{}': camera file '{}' has no pose (rvec/tvec)", dir, f);
  }
  FV_REQUIRE(!cams.empty(), "rig '{}' has no camera files (*.yaml)", dir);
  return cams;
}

}  // namespace fv::app
