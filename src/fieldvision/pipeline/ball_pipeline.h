// The multi-camera ball pipeline in one process: one thread per camera running a CameraStage
// (read a frame, detect ball candidates, send a CameraMessage) and a FusionStage (synchronise,
// triangulate robustly) in the calling thread, joined through bounded queues. Across processes
// the same stages are joined by ZeroMQ instead (net/node.h, net/fuse.h). Offline files block
// when a queue is full so no frame is lost; live input keeps the newest messages (QueuePolicy).
// Drops, duplicates and streams of different lengths are reported by the synchroniser.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/io/frame_source.h"
#include "fieldvision/pipeline/bounded_queue.h"
#include "fieldvision/pipeline/camera_stage.h"
#include "fieldvision/pipeline/frame_sync.h"
#include "fieldvision/pipeline/fusion_stage.h"
#include "fieldvision/pipeline/job.h"
#include "fieldvision/recon/triangulation.h"

namespace fv::pipeline {

struct BallPipelineOptions {
  SyncOptions sync;
  int queue_capacity = 3;                          // messages per camera queue (the seed's 3)
  QueuePolicy queue_policy = QueuePolicy::kBlock;  // kDropOldest for live input
  recon::TriangulationOptions triangulation;
  BallTrackOptions track;    // used with BallRegionDetectFn detectors
  long long max_frames = 0;  // stop each camera after this many frames; 0: all
  bool progress = true;      // frames, fps and time left on stderr
  // Offline (kBlock): fuse every frame a second time, second_pass_lag_s behind the first pass,
  // knowing each still airborne point from the first pass's sightings up to then (its future
  // included; FusionStage::RememberHovering), so a ghost is dropped from its first frame and not
  // only 0.3 s (HoverFilterOptions::min_span_s) later. on_frame sees the second pass's frames.
  bool second_pass = true;
  double second_pass_lag_s = 1.0;
  // The fusion hands the ball's 3D position back to the camera stages (ball_hints.h), with
  // tracked detectors and posed cameras.
  bool hints = true;
  BallHintOptions hint;
  JobControl* control = nullptr;  // optional: progress callback and stop check (not owned)
  // Optional: each camera message as the fusion takes it off its queue (in the fusion thread).
  std::function<void(const CameraMessage&)> on_message;
  void Check() const;  // throws fv::Error naming the bad field
};

struct BallPipelineSummary {
  int num_cameras = 0;
  std::vector<std::string> camera_names;  // Camera::name, or "camera <index>" if unnamed
  long long frames = 0;                   // synchronised frames
  long long frames_with_position = 0;     // 3D (or ground) positions
  long long ground_positions = 0;         // single-camera ground positions among them
  long long weak_positions = 0;       // positions completed with weak candidates (triangulation.h)
  long long hovering_dropped = 0;     // airborne points that stood still, dropped (HoverFilter)
  long long frames_few_blobs = 0;     // no position: fewer than 2 cameras had candidates
  long long frames_inconsistent = 0;  // no position although >= 2 cameras had candidates
  double mean_err_px = 0.0;           // mean of the positions' RMS reprojection errors
  std::vector<long long> used_per_camera;        // positions each camera contributed to
  std::vector<long long> candidates_per_camera;  // candidates each camera reported
  std::vector<size_t> queue_drops;               // messages dropped by the queues
  std::vector<long long> full_scans;             // frames searched whole, per camera
  std::vector<long long> window_scans;           // frames searched in a window, per camera
  std::vector<long long> guided;                 // guided fits (camera_stage.h), per camera
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
BallPipelineSummary RunBallPipeline(const std::vector<camera::Camera>& cameras,
                                    std::vector<std::unique_ptr<io::FrameSource>>& sources,
                                    const std::vector<BallDetectFn>& detectors,
                                    const BallPipelineOptions& options,
                                    const std::function<void(const BallFrame&)>& on_frame);
// The same with detectors that can search a window (options.track): each camera stage tracks
// the ball and decodes encoded frames (SourceFrame::jpeg) only where it looks. `guided`: empty,
// or a guided fit per camera (camera_stage.h; an empty one: none for that camera).
BallPipelineSummary RunBallPipelineTracked(const std::vector<camera::Camera>& cameras,
                                           std::vector<std::unique_ptr<io::FrameSource>>& sources,
                                           const std::vector<BallRegionDetectFn>& detectors,
                                           const BallPipelineOptions& options,
                                           const std::function<void(const BallFrame&)>& on_frame,
                                           const std::vector<BallGuidedFn>& guided = {});

// The stages of RunBallPipelineTracked, in order; each callable alone.
// Throws fv::Error for lists of different sizes, a missing video or detector, or a video whose
// frame size is not its camera's.
void CheckBallPipelineInputs(const std::vector<camera::Camera>& cameras,
                             const std::vector<std::unique_ptr<io::FrameSource>>& sources,
                             const std::vector<BallRegionDetectFn>& detectors);
// The camera names ("camera <index>" where unnamed) and zeroed per-camera counts.
BallPipelineSummary EmptyBallPipelineSummary(const std::vector<camera::Camera>& cameras);
// The frames the progress line expects: the longest stream (FrameSource::FrameCount), at most
// `max_frames` when > 0; -1 when unknown.
long long ExpectedPipelineFrames(const std::vector<long long>& frame_counts, long long max_frames);
// A camera thread: reads `source` through `stage` into `queue` until the end of the stream,
// `max_frames` (> 0) frames, `stopping()` or a closed queue; then closes the queue.
void ReadCameraStream(io::FrameSource& source, CameraStage& stage,
                      BoundedQueue<CameraMessage>& queue, long long max_frames,
                      const std::function<bool()>& stopping);
using CameraQueues = std::vector<std::unique_ptr<BoundedQueue<CameraMessage>>>;
// The fusion stage: synchronises the queues' messages, fuses each frame and calls `on_frame`,
// until every stream ended or `stopping()`; sets the summary's sync report and fusion counts.
// `hints` (optional): receives each first-pass 3D position and each pop (ball_hints.h).
void FuseCameraQueues(const std::vector<camera::Camera>& cameras, const CameraQueues& queues,
                      const BallPipelineOptions& options, long long total,
                      const std::function<bool()>& stopping,
                      const std::function<void(const BallFrame&)>& on_frame,
                      BallPipelineSummary* summary, BallHintBoard* hints = nullptr);
// Copies the fusion counts into the summary (mean error: the sum over the positions).
void AddFusionStats(const FusionStats& stats, BallPipelineSummary* summary);

}  // namespace fv::pipeline
