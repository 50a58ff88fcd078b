// Each camera's video with the ball the rig placed (`fieldvision ball --draw DIR`): the 3D
// position of BALL.csv projected at the ball's size (cyan), the camera's accepted candidates
// (its DET.csv, green), the camera and frame, a legend band; frames paired by index.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"

namespace fv::pipeline {

// File names for the cameras' videos from their names: characters other than letters, digits,
// '-', '_' and '.' become '_', a leading '.' gets a '_' before it, an empty name is camN, and a
// name already taken gets -2, -3, ...
std::vector<std::string> DrawNames(const std::vector<std::string>& names);

struct BallOverlayOptions {
  std::string dir;  // the videos' folder (it must exist)
  // The videos' names, one per camera (NAME.mp4, or .avi without an H.264 encoder); empty:
  // DrawNames of the cameras' names.
  std::vector<std::string> names;
  double ball_diameter_m = 0.22;  // the drawn circle's size
  // Frame rate of image sequences (`ball --fps`; io::VideoSourceOptions::fps): 0 takes a synth
  // scene.json's, else 30 stands in. Videos keep their own.
  double fps = 0.0;
  long long max_frames = 0;  // frames drawn per camera (<= 0: all)
  bool progress = true;      // on a terminal
  void Check() const;        // throws fv::Error naming the bad option
};

struct BallOverlayResult {
  std::vector<std::string> videos;  // written, one per camera
  long long frames = 0;             // drawn, all cameras together
  long long balls_drawn = 0;        // of those, frames whose 3D ball lies in the image
  std::string Summary() const;
};

// `detections`: one DET.csv per camera (may be empty: no candidates drawn). Throws fv::Error
// naming the file for an unreadable video, BALL.csv or DET.csv, or a live source (its frames now
// are not the run's).
BallOverlayResult DrawBallOverlays(const std::vector<camera::Camera>& cameras,
                                   const std::vector<std::string>& videos,
                                   const std::string& ball_csv,
                                   const std::vector<std::string>& detections,
                                   const BallOverlayOptions& options);

}  // namespace fv::pipeline
