// The multi-camera ball pipeline: one thread per camera (read a frame, detect ball candidates,
// send a CameraMessage) and one fusion stage (synchronise, triangulate robustly), joined through
// bounded queues, as in the seed's one-process-per-camera server. Offline files block when a
// queue is full so no frame is lost; live input keeps the newest messages (QueuePolicy).
// Drops, duplicates and streams of different lengths are reported by the synchroniser.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/pipeline/bounded_queue.h"
#include "fieldvision/pipeline/frame_source.h"
#include "fieldvision/pipeline/frame_sync.h"
#include "fieldvision/recon/triangulation.h"

namespace fv {

// A camera stage's detector: the ball candidates of one BGR frame, best first. Called from that
// camera's thread only.
using BallDetectFn = std::function<std::vector<BallObservation>(const cv::Mat& bgr)>;
// A detector that can search a region only (roi empty: the whole frame). Pixels of `bgr` outside
// roi may be stale and must not be read. Weak candidates are never tracked.
using BallRegionDetectFn =
    std::function<std::vector<BallObservation>(const cv::Mat& bgr, const cv::Rect& roi)>;

// Ball tracking in each camera stage: search a window around where the ball was last seen
// (constant velocity in the image), decoding only that part of Motion-JPEG frames; the whole
// frame when the window has no accepted candidate, when the ball was not seen in the previous
// frame, and at least every full_scan_every frames (a second ball-like object, a wrong lock).
struct BallTrackOptions {
  bool enabled = true;
  int full_scan_every = 20;
  double window_radii = 6.0;  // half-size of the window in ball radii, plus the image motion
  int min_window_px = 40;     // half-size of the window at least
  void Check() const;         // throws fv::Error naming the bad field
};

struct BallPipelineOptions {
  SyncOptions sync;
  int queue_capacity = 3;                          // messages per camera queue (the seed's 3)
  QueuePolicy queue_policy = QueuePolicy::kBlock;  // kDropOldest for live input
  TriangulationOptions triangulation;
  BallTrackOptions track;    // used with BallRegionDetectFn detectors
  long long max_frames = 0;  // stop each camera after this many frames; 0: all
  bool progress = true;      // frames, fps and time left on stderr
  void Check() const;        // throws fv::Error naming the bad field
};

// The fused result of one synchronised frame.
struct BallFrame {
  long long frame = 0;
  double time_s = 0.0;
  int cameras_present = 0;     // cameras with a message for this frame
  int cameras_with_blobs = 0;  // of those, cameras with at least one candidate
  TriangulationResult result;
};

struct BallPipelineSummary {
  int num_cameras = 0;
  std::vector<std::string> camera_names;  // Camera::name, or "camera <index>" if unnamed
  long long frames = 0;                   // synchronised frames
  long long frames_with_position = 0;     // 3D (or ground) positions
  long long ground_positions = 0;         // single-camera ground positions among them
  long long weak_positions = 0;       // positions completed with weak candidates (triangulation.h)
  long long frames_few_blobs = 0;     // no position: fewer than 2 cameras had candidates
  long long frames_inconsistent = 0;  // no position although >= 2 cameras had candidates
  double mean_err_px = 0.0;           // mean of the positions' RMS reprojection errors
  std::vector<long long> used_per_camera;        // positions each camera contributed to
  std::vector<long long> candidates_per_camera;  // candidates each camera reported
  std::vector<size_t> queue_drops;               // messages dropped by the queues
  std::vector<long long> full_scans;             // frames searched whole, per camera
  std::vector<long long> window_scans;           // frames searched in a window, per camera
  std::vector<long long> bad_frames;             // encoded frames that could not be decoded
  std::vector<std::string> first_bad_frame;      // the error of the first of them
  SyncReport sync;
  double seconds = 0.0;
  double fps = 0.0;              // synchronised frames per second of wall time
  std::string ToString() const;  // a few lines for the console
};

// Runs the pipeline over `sources` (one per camera, same order as `cameras` and `detectors`)
// and calls `on_frame` in the calling thread for every synchronised frame, in order. Throws
// fv::Error for mismatched list sizes, a frame size that differs from its camera file, or an
// error in any stage (the other stages are stopped first).
BallPipelineSummary RunBallPipeline(const std::vector<Camera>& cameras,
                                    std::vector<std::unique_ptr<FrameSource>>& sources,
                                    const std::vector<BallDetectFn>& detectors,
                                    const BallPipelineOptions& options,
                                    const std::function<void(const BallFrame&)>& on_frame);
// The same with detectors that can search a window (options.track): each camera stage tracks
// the ball and decodes encoded frames (SourceFrame::jpeg) only where it looks.
BallPipelineSummary RunBallPipelineTracked(const std::vector<Camera>& cameras,
                                           std::vector<std::unique_ptr<FrameSource>>& sources,
                                           const std::vector<BallRegionDetectFn>& detectors,
                                           const BallPipelineOptions& options,
                                           const std::function<void(const BallFrame&)>& on_frame);

// The fusion of one synchronised frame (what the fusion stage does per frame).
BallFrame FuseFrame(const std::vector<Camera>& cameras, const SyncedFrame& frame,
                    const TriangulationOptions& options, const Eigen::Vector3d* prior = nullptr);

// The ball's expected position from the last positions (constant velocity over the last two,
// when they are at most max_gap frames apart and the newest is at most max_gap frames old).
class BallPredictor {
 public:
  explicit BallPredictor(int max_gap = 5) : max_gap_(max_gap) {}
  void Add(long long frame, const Eigen::Vector3d& point_world);
  std::optional<Eigen::Vector3d> Predict(long long frame) const;

 private:
  int max_gap_;
  int count_ = 0;
  long long frame_[2] = {0, 0};  // [0] newest
  Eigen::Vector3d point_[2];
};

}  // namespace fv
