// A moving camera's view held to the painted field lines: a frame's homography to the first view
// (CameraMotion: each new keyframe's, a frame matched to no other at its predicted view, and any
// other frame whose line pixels lie off the field's lines under its registered view) gives its
// pose, the first camera turned about its centre (a camera that moves: the pose that sees the
// ground through it, Zhang 2000); the frame's line pixels refine that rotation (or the whole
// pose; calib::RefineWithLinePixels, chamfer matching on the ground plane) and the ground
// plane's homography between the refined pose and the first pose replaces the registered one
// (Hartley & Zisserman 13.1). Taken only when the lines hold it: lines across each other, the
// pixels on them after the fit, a correction of a drift's size (lines matched to the wrong ones
// fail these). The registration's drift and its single frames off (a fit over grass) stop
// wherever enough lines are seen.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/calib/lines.h"
#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"

namespace fv::track {

struct LineAnchorOptions {
  calib::RefineOptions refine = DefaultRefine();
  // Line pixels within refine.gate_m of a line after the fit, fewer: the frame's view is kept.
  int min_inliers = 150;
  // The lines fitted must hold the view both ways on the ground: the smaller eigenvalue of the
  // scatter of the fitted line pixels' line normals over the larger (0: all lines parallel, the
  // view free to slide along them; 1: as much across as along) at least this.
  double min_crossing = 0.1;
  // Frames wider than this are searched for line pixels at this width (the pixels found are
  // scaled back): at 1920x1080 finding them took 77 ms a frame.
  int work_width_px = 960;
  // Frames between keyframes are checked too: when their line pixels lie over refit_above_px
  // (median) from the field's lines under the registered view, they are fitted as keyframes.
  bool every_frame = true;
  double refit_above_px = 1.0;
  // The fitted line pixels' median distance from their lines, in pixels, at most this (a pose
  // matching lines to the wrong ones leaves many far off).
  double max_median_px = 2.0;
  // A correction that moves a point of the frame on the first view by more than this share of
  // the image width is taken for lines matched to the wrong ones: the registered view is kept (a
  // view 150 px off was fitted to the lines 57 px from the truth, passing the checks above).
  double max_correction_share = 0.05;
  void Check() const;  // throws fv::Error naming the bad field
  // Line refinement for a frame already registered: a coarse 20 mm table and the rotation only,
  // the camera's centre held where the camera file puts it (fix_centre: a camera on a tripod or
  // held still turns about a point near it; over a turning camera's lines a free centre left the
  // views 0.6-0.8 px off on the ground against 0.03-0.26 px). A camera that moves (a drone):
  // fix_centre false, each frame's pose taken from its ground homography (PlanePose) and refined
  // whole, its centre moving at most max_move_m (1 m) from there.
  static calib::RefineOptions DefaultRefine();
};

struct LineAnchorStats {
  int checked = 0;   // frames between keyframes whose line pixels were checked (every_frame)
  int tried = 0;     // views fitted (keyframes, frames matched to no other, frames off the lines)
  int anchored = 0;  // of those, views the lines corrected
  std::vector<double> corrections_px;  // anchored frames' largest correction on the first view
  std::string Summary() const;
};

class LineAnchor {
 public:
  // `first`: the camera file (lens and the first frame's pose); `field` must have painted lines.
  // Throws fv::Error when the camera has no pose or the field no lines.
  LineAnchor(const camera::Camera& first, const field::FieldModel& field,
             const LineAnchorOptions& options = {});
  // The frame's homography from its undistorted pixels to the first frame's, corrected by its
  // line pixels (those inside the people's boxes left out), or nullopt when the lines do not
  // hold it (too few, the fit refused, a correction too large).
  std::optional<cv::Matx33d> Correct(const cv::Mat& bgr, const std::vector<cv::Rect2d>& people,
                                     const cv::Matx33d& first_from_frame, bool keyframe = true);
  const LineAnchorStats& stats() const { return stats_; }

  // The pose of a frame whose undistorted pixels map to the first view's by `first_from_frame`:
  // the first camera turned about its centre (refine.fix_centre), or else the pose that sees the
  // ground through that homography (PlanePose).
  camera::Camera FramePose(const cv::Matx33d& first_from_frame) const;
  // The pose, centre and rotation, under which the ground maps to the frame's undistorted pixels
  // as it does through `first_from_frame` and the first view (a camera that moves).
  camera::Camera PlanePose(const cv::Matx33d& first_from_frame) const;
  // The homography of the ground plane from `frame`'s undistorted pixels to the first view's.
  cv::Matx33d GroundHomography(const camera::Camera& frame) const;

 private:
  // The largest move between the registered and the held view of a point of the frame (posed
  // as `frame`) on the first view, over the ground it sees.
  double Correction(const camera::Camera& frame, const cv::Matx33d& registered,
                    const cv::Matx33d& held) const;
  // The frame's line pixels seen by `frame` (found at work_width_px).
  std::vector<Eigen::Vector2d> LinePixels(const cv::Mat& bgr, const camera::Camera& frame) const;

  camera::Camera first_;
  field::FieldModel field_;
  LineAnchorOptions options_;
  calib::LineDistanceMap map_;  // built once for all the frames
  cv::Matx33d k_;
  LineAnchorStats stats_;
};

}  // namespace fv::track
