// A folder of camera files (a rig: `calibrate multi --out DIR`, `calibrate import --out DIR`) as
// the calibrate commands read it: every *.yaml / *.yml in it, by file name.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"

namespace fv::app {

// The camera file at `path`, named by its `name` or else the file's stem.
camera::Camera ReadNamedCamera(const std::string& path);

// The camera files in `dir`, sorted; throws "rig 'dir' is not a folder" when it is not one.
std::vector<std::string> CameraFilesIn(const std::string& dir);

// Every camera file in `dir` read, each named by its `name` or else its file's stem; throws when
// `dir` holds none or, with `require_pose`, when one has no pose.
std::vector<camera::Camera> ReadCameraFolder(const std::string& dir, bool require_pose = false);

// Camera i's name, else "cam<i+1>".
std::string CameraNameOr(const camera::Camera& camera, size_t i);

// Where each camera's file goes in `dir`: NAME.yaml, NAME CameraNameOr made a safe file
// name (util::FileNamePart: never a path, "../x" stays in `dir`). Throws naming `what` and `dir`
// when `dir` is a file or two cameras would share a file; nothing is made.
std::vector<std::string> CameraFilePaths(const std::vector<camera::Camera>& cams,
                                         const std::string& dir, const std::string& what);

}  // namespace fv::app
