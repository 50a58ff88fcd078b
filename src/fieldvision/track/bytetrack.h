// Multi-object tracking by detection, ByteTrack (Zhang et al., ECCV 2022): a constant-velocity
// Kalman filter per box, high-score then low-score detections matched by the Hungarian method on
// IoU, with a calibrated camera also the foot points' distance on the field, and torso-colour
// appearance (as DeepSORT) for matching and re-finding lost tracks; optional OpenCV single-target
// trackers (CSRT, KCF, MOSSE) through missed detections.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/track/detection.h"

namespace fv::track {

struct FrameDetections;

struct TrackerOptions {
  double high_score = 0.5;          // detections at or above take part in the first association
  double low_score = 0.2;           // detections in [low_score, high_score) in the second one
  double new_track_score = 0.55;    // lowest score that starts a new track
  double match_iou = 0.2;           // first association: lowest IoU (1 - cost)
  double low_match_iou = 0.4;       // second association: lowest IoU
  double field_gate_m = 1.5;        // field association: largest foot distance per frame step
  double field_weight = 0.5;        // share of the field distance in the cost (0: IoU only)
  int max_lost_frames = 40;         // frames a lost track is kept for re-finding
  int min_hits = 2;                 // matched frames before a new track is reported
  double reid_max_distance = 0.35;  // Bhattacharyya distance of torso histograms to re-find
  double reid_speed_mps = 3.0;      // reach of re-finding: metres per second lost (field)
  double reid_speed_px = 12.0;      // same without a calibrated camera: pixels per frame
  double fps = 25.0;                // frame rate of the video (for reach in metres)
  // First association: share of the torso-colour distance (Bhattacharyya, 0..1, between the
  // track's running histogram and the detection's) in the cost (0: motion only). Needs frames.
  double appearance_weight = 0.5;
  // The track's histogram follows its detections with this weight per frame (exponential moving
  // average), from confident detections that no other detection overlaps.
  double appearance_momentum = 0.1;
  // The bottom edge of a box is the near edge of the feet: the person's ground position is this
  // far behind it, away from the camera (synthetic scenes: about 0.2 m).
  double foot_offset_m = 0.2;
  std::string sot = "none";  // none | csrt | kcf | mosse: single-target tracker through misses

  void Check() const;
};

// One tracked person in one frame.
struct TrackState {
  int id = 0;
  cv::Rect2d box;
  double score = 0.0;                      // score of the matched detection (0 when predicted)
  std::optional<Eigen::Vector2d> field_m;  // foot point on the ground plane (calibrated camera)
  bool predicted = false;                  // no detection this frame (SOT or Kalman only)
};

struct TrackerStats {
  int frames = 0;
  int tracks_started = 0;  // ids given out
  int refound = 0;         // lost tracks re-found by appearance
  int first_stage_matches = 0;
  int second_stage_matches = 0;
  std::string Summary() const;
};

class ByteTracker {
 public:
  // `camera` (may be null or without pose) enables the association on the field plane.
  ByteTracker(const TrackerOptions& options, const camera::Camera* camera);
  ~ByteTracker();
  // One frame's detections (and the frame, for appearance and SOT; may be empty) -> the tracks
  // reported in this frame.
  std::vector<TrackState> Update(const std::vector<Detection>& detections, const cv::Mat& frame);
  const TrackerStats& stats() const { return stats_; }

  struct Track;

 private:
  void PredictTracks(const cv::Mat& frame);
  void Apply(Track& t, int d, const std::vector<Detection>& detections, FrameDetections& fd);
  int Associate(const std::vector<Track*>& ts, const std::vector<int>& ds, double min_iou,
                bool full, const std::vector<Detection>& detections, FrameDetections& fd);
  void AssociateAll(const std::vector<Detection>& detections, FrameDetections& fd);
  void ConfirmOrMiss(const cv::Mat& frame);
  bool CarryBySot(Track& t, const cv::Mat& frame);
  void RefindOrStart(const std::vector<Detection>& detections, FrameDetections& fd,
                     const cv::Mat& frame);
  void DropExpired();
  std::vector<TrackState> Report() const;

  TrackerOptions o_;
  std::optional<camera::Camera> camera_;
  std::vector<std::unique_ptr<Track>> tracks_;
  cv::Mat previous_frame_;
  int next_id_ = 1;
  int frame_ = 0;
  TrackerStats stats_;
};

// Where the ray through pixel `uv` is at height `height_m` (the ground position below that
// point), moved `offset_m` horizontally away from the camera; nullopt when the ray does not reach
// that height in front of the camera.
std::optional<Eigen::Vector2d> GroundBelowPixel(const camera::Camera& camera,
                                                const Eigen::Vector2d& uv, double height_m,
                                                double offset_m = 0.0);

// Ground position of a person's box: the bottom centre on the plane z = 0, moved `offset_m`
// horizontally away from the camera; nullopt when the ray misses the ground.
std::optional<Eigen::Vector2d> FootOnGround(const camera::Camera& camera, const cv::Rect2d& box,
                                            double offset_m = 0.0);

// HSV hue-saturation histogram (normalised) of the torso part of a box; empty when the box is
// outside the frame.
cv::Mat TorsoHistogram(const cv::Mat& bgr, const cv::Rect2d& box);

}  // namespace fv::track
