// Whether a still camera's view stays put: every few frames are registered to the first as a
// moving camera's are (CameraMotion: optical flow and a homography off the people's boxes), and
// the farthest the image centre moves is kept. A camera knocked, swaying or panning moves it; a
// still run's field positions then silently go wrong, so `players` warns and names
// --moving-camera.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/track/camera_motion.h"

namespace fv::track {

struct ViewDriftOptions {
  int every_frames = 10;  // frames between two checks (the first frame is the reference)
  // The view counts as moved when its centre moves by more than this share of the frame's width
  // (a tripod in wind wobbles by a pixel or two).
  double moved_share = 0.01;
  void Check() const;  // throws fv::Error naming the bad field
};

struct ViewDriftStats {
  int checked = 0;                // frames registered to the first
  int unmatched = 0;              // of those, matched to none (no measurement)
  double max_shift_px = 0.0;      // the farthest the image centre moved, pixels of the frame
  int max_frame = 0;              // the frame (0-based) where it did
  bool mostly_unmatched = false;  // over half the checks (from the fourth) matched to none
  bool moved = false;             // that, or max_shift_px over moved_share of the width
  std::string Summary() const;
};

class ViewDrift {
 public:
  explicit ViewDrift(const ViewDriftOptions& options = {});
  // Frame `index` (0-based, in order; 8-bit BGR) with the people's boxes: the first is the
  // reference, every every_frames-th after it is registered to it.
  void Add(int index, const cv::Mat& bgr, const std::vector<cv::Rect2d>& people);
  const ViewDriftStats& stats() const { return stats_; }

 private:
  ViewDriftOptions options_;
  CameraMotion motion_;
  int width_ = 0;
  ViewDriftStats stats_;
};

}  // namespace fv::track
