// Field-position error of player tracks against annotated boxes: in each frame the estimated
// boxes are matched one-to-one to the ground truth's (IoU >= a threshold, Hungarian), and the
// track's position (x_m, y_m) is compared with the ground truth's, its own or its box's foot
// point through the camera (PlaceFeet, the players' own mapping). With the same camera on both
// sides this measures what the tracker adds: foot points of partly hidden people, smoothing, gaps
// filled; not the camera's error. Rows whose box is much shorter than the annotated one (legs
// hidden in the estimate) are reported apart.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/track/view_canvas.h"

namespace fv::track {

struct PositionEvalOptions {
  double iou_threshold = 0.5;  // a match needs IoU >= this (as MotOptions)
  int frame_offset = 0;        // added to the estimate's frame numbers (as MotOptions)
  // An estimated box under this share of its annotated box's height is "short": its bottom is
  // not the annotated foot (hidden legs, a box cut by another person).
  double short_height_ratio = 0.85;
  void Check() const;  // throws fv::Error naming the bad field
};

struct PositionErrors {
  int gt_boxes = 0;          // ground truth scored: no class, or conf > 0 and a pedestrian
  int matched = 0;           // estimated rows matched to one of them
  int without_position = 0;  // matched, but either side has no field position
  // Horizontal distance between the matched positions (metres), all rows and the short ones.
  std::vector<double> errors_m, short_errors_m;
  std::string Summary() const;
  std::string ToJson() const;
};

// Fills x_m, y_m of rows that have none with the box's foot point on the ground (FootOnGround,
// moved foot_offset_m away from the camera as the tracker does); a box whose bottom ray misses the
// ground keeps none. Throws when the camera has no pose.
void PlaceFeet(const camera::Camera& camera, double foot_offset_m, std::vector<TrackRow>* rows);
// The same for a moving camera's frames (players --moving-camera, motion_file.h): each row's box
// is placed through the canvas where its frame lies, with the canvas's camera (posed); rows of
// frames beyond the canvas's keep none.
void PlaceFeet(const ViewCanvas& canvas, double foot_offset_m, std::vector<TrackRow>* rows);

PositionErrors EvaluatePositions(const std::vector<TrackRow>& gt, const std::vector<TrackRow>& est,
                                 const PositionEvalOptions& options = {});

}  // namespace fv::track
