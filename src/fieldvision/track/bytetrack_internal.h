// ByteTracker's track state and the stages of ByteTracker::Update that carry logic, for tests.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/tracking.hpp>
#include <opencv2/tracking/tracking_legacy.hpp>
#include <opencv2/video/tracking.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/track/bytetrack.h"

namespace fv::track {

enum class TrackPhase { kNew, kTracked, kLost };

// One track: a constant-velocity Kalman filter on (centre x, centre y, aspect, height).
struct ByteTracker::Track {
  int id = 0;  // 0 until confirmed
  TrackPhase state = TrackPhase::kNew;
  cv::KalmanFilter kf{8, 4, 0, CV_32F};
  int hits = 0;
  int lost_frames = 0;
  bool matched = false;
  double score = 0;
  cv::Rect2d box;  // corrected (or predicted) box
  std::optional<Eigen::Vector2d> field_m;
  cv::Mat hist;
  cv::Ptr<cv::Tracker> sot;
  cv::Ptr<cv::legacy::Tracker> sot_legacy;
  bool sot_box = false;  // this frame's box came from the SOT

  void Init(const cv::Rect2d& b);
  void Predict();
  void Correct(const cv::Rect2d& b);
  void ResetSot();
};

// One frame's detections as the associations use them.
struct FrameDetections {
  std::vector<int> high;                                // score >= high_score
  std::vector<int> low;                                 // score in [low_score, high_score)
  std::vector<std::optional<Eigen::Vector2d>> field_m;  // foot points (calibrated camera)
  std::vector<cv::Mat> hist;  // torso histograms of the high ones (with a frame)
  std::vector<char> clear;    // no other detection overlaps it: its histogram may update a track
  std::vector<char> used;     // matched in this frame
};

// Splits detections by score, with foot points (camera may be null) and torso histograms.
FrameDetections SortDetections(const std::vector<Detection>& detections, const cv::Mat& frame,
                               const TrackerOptions& o, const camera::Camera* camera);

// A lost track whose predicted foot point left the image has left the scene.
bool LeftImage(const ByteTracker::Track& t, const cv::Size& frame);

// Cost of pairing track t with detection d; >= 1e9 when not allowed. The field distance and the
// appearance take part when `full` (associations of high-score detections); otherwise IoU only.
double PairCost(const ByteTracker::Track& t, const std::vector<Detection>& detections,
                const FrameDetections& fd, int d, double min_iou, bool full,
                const TrackerOptions& o);

// Whether a lost track may be re-found at detection d: within the distance a person walks in the
// time lost (on the field with foot points, else in pixels).
bool InReidReach(const ByteTracker::Track& t, const Detection& det,
                 const std::optional<Eigen::Vector2d>& det_field_m, const TrackerOptions& o);

}  // namespace fv::track
