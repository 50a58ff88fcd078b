// Calibrations made by other tools, as fv::camera::Camera (and back): anipose / aniposelib and
// Pose2Sim `calibration.toml` / `Calib.toml` (per camera a [section] with name, size [w, h], matrix
// 3x3, distortions [k1 k2 p1 p2 (k3)], rotation (Rodrigues rvec) and translation, world to camera
// as OpenCV), and OpenCV's stereo calibration files (stereo_calib.cpp's intrinsics.yml M1 D1 M2 D2
// and extrinsics.yml R T, camera 2 from camera 1). Qualisys `.qca.txt` is read by pose2sim.h.
// TOML is read with toml++ (Debian's libtomlplusplus-dev); the writer prints the subset these
// tools read, in their layout.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"

namespace fv::calib {

// Cameras of a calibration.toml (sections with a `matrix`, in file order). Translations are
// multiplied by metres_per_unit (Pose2Sim: metres, 1; anipose: the board's unit, often mm,
// 0.001). Throws fv::Error naming the file, section and key.
std::vector<camera::Camera> ReadCalibrationToml(const std::string& path,
                                                double metres_per_unit = 1.0);

// Writes cameras (with poses) as a Pose2Sim / anipose calibration.toml in metres; temporary file
// first, then renamed.
void WriteCalibrationToml(const std::vector<camera::Camera>& cameras, const std::string& path);

// OpenCV stereo files: the keys M1 D1 M2 D2 (and R T, camera 2 from camera 1; without them the
// cameras have no pose) from one or more files; the image size is not in them. T is multiplied by
// metres_per_unit (stereo_calib.cpp uses the square side as unit). Camera 1 is the reference
// (identity pose).
std::vector<camera::Camera> ReadOpenCvStereo(const std::vector<std::string>& paths, int width,
                                             int height, double metres_per_unit = 1.0);

// Parses "1920x1080"; throws naming `what` otherwise.
void ParseImageSize(const std::string& text, const std::string& what, int* width, int* height);

}  // namespace fv::calib
