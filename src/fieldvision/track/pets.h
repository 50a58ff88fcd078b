// Imports of the PETS 2009 data: the CVML ground-truth XML (frames of objects with boxes given as
// centre and size, see gt_file_format.txt) as MOT rows, and a Tsai camera calibration (Tsai 1987,
// "A versatile camera calibration technique...", as in the PETS/OpenTraj View_NNN.xml: focal and
// sensor geometry in millimetres, kappa1 radial distortion, rotation Rx/Ry/Rz in radians and
// translation in millimetres) as an OpenCV camera. Tsai's model maps distorted sensor coordinates
// to undistorted ones (Xu = Xd (1 + kappa1 r_d^2)), the inverse direction of OpenCV's, so the
// OpenCV coefficients k1, k2, k3 are fitted to Tsai's mapping by linear least squares over the
// image radius; lengths are converted to metres.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/track/mot.h"

namespace fv::track {

// Every <object> box of every <frame> (conf 1, no field position) as MOT rows: frames numbered
// from 1 (CVML's frame 0 is MOT frame 1, the video's first frame). Throws naming the file.
std::vector<TrackRow> ReadPetsCvml(const std::string& path);

struct TsaiParameters {
  int width = 0, height = 0;
  double ncx = 0, nfx = 0, dx = 0, dy = 0, dpx = 0, dpy = 0;  // sensor (mm)
  double focal_mm = 0, kappa1 = 0, cx = 0, cy = 0, sx = 1;    // kappa1 in 1/mm^2, cx/cy pixels
  double rx = 0, ry = 0, rz = 0;                              // radians
  double tx_mm = 0, ty_mm = 0, tz_mm = 0;
};

TsaiParameters ReadTsaiXml(const std::string& path);

// Tsai's exact projection of a world point (metres) to pixels (for checks).
Eigen::Vector2d TsaiProject(const TsaiParameters& p, const Eigen::Vector3d& world_m);

struct TsaiConversion {
  camera::Camera camera;
  double max_fit_error_px = 0;  // largest difference from Tsai's projection over the image
  std::string Summary() const;
};

// The OpenCV camera (k1, k2, p1 = p2 = 0, k3 fitted) equivalent to Tsai's model; world in metres.
TsaiConversion CameraFromTsai(const TsaiParameters& p, const std::string& name = "");

}  // namespace fv::track
