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

}  // namespace fv::app
