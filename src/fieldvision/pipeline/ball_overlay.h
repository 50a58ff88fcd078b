// Each camera's video with the ball the rig placed (`fieldvision ball --draw DIR`): per frame the
// 3D position of BALL.csv projected into the camera as a circle of the ball's projected size
// (cyan), that camera's accepted candidates (its DET.csv, green, with their scores), the frame
// and time, and a legend band below; one playable video per camera (track::PlayableVideoWriter),
// frames paired by index (`ball --sync frame`). What a user looks at to trust a 3D position, or
// to see which camera pulled it off.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"

namespace fv::pipeline {

struct BallOverlayOptions {
  std::string dir;                // the videos' folder (made)
  double ball_diameter_m = 0.22;  // the drawn circle's size
  long long max_frames = 0;       // frames drawn per camera (<= 0: all)
  bool progress = true;           // on a terminal
  void Check() const;             // throws fv::Error naming the bad option
};

struct BallOverlayResult {
  std::vector<std::string> videos;  // written, one per camera
  long long frames = 0;             // drawn, all cameras together
  long long balls_drawn = 0;        // of those, frames whose 3D ball lies in the image
  std::string Summary() const;
};

// `detections`: one DET.csv per camera (may be empty: no candidates drawn). Throws fv::Error
// naming the file for an unreadable video, BALL.csv or DET.csv.
BallOverlayResult DrawBallOverlays(const std::vector<camera::Camera>& cameras,
                                   const std::vector<std::string>& videos,
                                   const std::string& ball_csv,
                                   const std::vector<std::string>& detections,
                                   const BallOverlayOptions& options);

}  // namespace fv::pipeline
