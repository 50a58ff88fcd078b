#include "fieldvision/app/camera_folder.h"

#include <algorithm>
#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

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

std::string CameraNameOr(const camera::Camera& camera, size_t i) {
  return camera.name.empty() ? fmt::format("cam{}", i + 1) : camera.name;
}

void CheckRigOutput(const std::vector<std::string>& paths, const std::string& dir,
                    const std::vector<std::string>& inputs, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  FV_REQUIRE(!fs::exists(dir, ec) || fs::is_directory(dir, ec),
             "{} '{}' is a file: give a folder (one NAME.yaml per camera is written there)", what,
             dir);
  for (size_t i = 0; i < paths.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      FV_REQUIRE(!util::SameFile(paths[i], paths[j]),
                 "two cameras would both be written to '{}' in {} '{}': rename one", paths[i], what,
                 dir);
    }
    util::CheckOutputPath(paths[i], inputs, what);
  }
  if (!fs::is_directory(dir, ec)) return;
  for (const std::string& file : CameraFilesIn(dir)) {
    const bool ours = std::any_of(paths.begin(), paths.end(),
                                  [&](const std::string& p) { return util::SameFile(p, file); });
    FV_REQUIRE(ours,
               "{} '{}' already holds the camera file '{}', which this run does not write: the "
               "folder would mix two calibrations; give a new or empty folder",
               what, dir, fs::path(file).filename().string());
  }
}

std::vector<std::string> CameraFilePaths(const std::vector<camera::Camera>& cams,
                                         const std::string& dir, const std::string& what,
                                         const std::vector<std::string>& inputs) {
  std::vector<std::string> paths;
  std::map<std::string, std::string> named;  // file -> the camera's name
  for (size_t i = 0; i < cams.size(); ++i) {
    const std::string name = CameraNameOr(cams[i], i);
    const std::string file = util::FileNamePart(name) + ".yaml";
    const auto [at, fresh] = named.emplace(file, name);
    FV_REQUIRE(fresh, "{} would both be written to '{}' in {} '{}': rename one",
               at->second == name ? fmt::format("two cameras named '{}'", name)
                                  : fmt::format("cameras '{}' and '{}'", at->second, name),
               file, what, dir);
    paths.push_back((std::filesystem::path(dir) / file).string());
  }
  CheckRigOutput(paths, dir, inputs, what);
  return paths;
}

}  // namespace fv::app
