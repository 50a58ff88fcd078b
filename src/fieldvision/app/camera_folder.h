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

// Checks `paths` as the camera files a run writes into the folder `dir` (`what`: the option)
// before anything is written: `dir` is no file, no two paths are one file, none is one of
// `inputs`, and `dir` holds no other camera file (*.yaml, *.yml): the rig commands read every
// camera file of a folder, so an earlier calibration's cameras would mix in. Throws fv::Error
// naming `what`, `dir` and the file.
void CheckRigOutput(const std::vector<std::string>& paths, const std::string& dir,
                    const std::vector<std::string>& inputs, const std::string& what);

// Where each camera's file goes in `dir`: NAME.yaml, NAME CameraNameOr made a safe file
// name (util::FileNamePart: never a path, "../x" stays in `dir`), checked by CheckRigOutput
// (two cameras sharing a file are named). Throws fv::Error naming `what` and `dir`; nothing is
// made.
std::vector<std::string> CameraFilePaths(const std::vector<camera::Camera>& cams,
                                         const std::string& dir, const std::string& what,
                                         const std::vector<std::string>& inputs = {});

}  // namespace fv::app
