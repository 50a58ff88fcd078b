// The `fieldvision ball` job as a library function: reads the camera files, opens the videos
// (checking each frame size against its camera file), builds one detect/BallDetector per camera,
// runs the ball pipeline, writes BALL.csv (frame,time_s,x_m,y_m,z_m,n_cams,err_px, one row per
// frame with a position) and, given a truth file, evaluates it (recon/ball_eval.h).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/camera_background.h"
#include "fieldvision/detect/dnn_ball.h"
#include "fieldvision/pipeline/ball_pipeline.h"
#include "fieldvision/pipeline/detections_job.h"
#include "fieldvision/recon/ball_eval.h"

namespace fv::pipeline {

struct BallJobOptions {
  std::vector<std::string> cameras;     // camera files, paired with `videos` in order
  std::vector<std::string> videos;      // files OpenCV reads or patterns such as dir/%05d.jpg
  std::vector<std::string> timestamps;  // optional: one frame,time_s CSV per video
  // Frames per second of image sequences, which have none of their own: without this or
  // `timestamps` the job refuses them rather than assume one. A video's own rate must agree with
  // it (within 1 %). 0: none given.
  double fps = 0.0;
  double ball_diameter_m = 0.22;
  std::string colour = "orange";  // colour preset or colour file (detect/colour.h)
  detect::DnnBallOptions dnn;     // --detector colour|dnn|both (detect/dnn_ball.h)
  std::string field;              // optional field (name or JSON): detect only over it
  std::string out;                // BALL.csv
  // Optional, one per camera: its accepted candidates as DET.csv (frame,time_s,u,v,radius_px,
  // score; what `ball --detections` reads), to fuse again with other settings.
  std::vector<std::string> detections_out;
  // Offline (not live): refine each flight on the cameras' accepted candidates at the end
  // (detections_job.h's physics-constrained bundle, 1-sigma bundle_sigma_px); positions inside a
  // refined flight are the flight model's.
  bool bundle = true;
  double bundle_sigma_px = 2.0;
  std::string truth;  // optional truth.csv for the error table
  // "frame" pairs frames by index; "time" by timestamps (the CSVs, else the container's).
  std::string sync = "frame";
  bool live = false;  // keep the newest messages (drop the oldest) instead of blocking
  // Offline (not live): a low-contrast candidate that stands apart from its camera's background
  // is taken as standing out (camera_background.h; a static camera's view).
  bool background = true;
  detect::CameraBackgroundOptions background_options;
  BallPipelineOptions pipeline;
  recon::BallEvalOptions eval;
  void Check() const;  // throws fv::Error naming the bad option
};

struct BallJobResult {
  BallPipelineSummary summary;
  std::optional<recon::BallEvalResult> eval;  // when a truth file was given
  long long rows_written = 0;
  std::optional<FlightBundle> bundle;     // offline with `bundle`
  std::vector<std::string> backgrounds;   // per camera, NeededBackgroundSummary
  std::vector<std::string> frames_notes;  // per camera, FrameSource::FramesNote after opening
  // One line when not one frame got a position (a wrong colour, unposed cameras): why, from the
  // summary; "" otherwise. BALL.csv then holds its header only (a video without the ball).
  std::string NoPositionWarning() const;
};

BallJobResult RunBallJob(const BallJobOptions& options);

// A rig camera from its file: the pose is required; `name` defaults to the file's stem.
camera::Camera ReadRigCamera(const std::string& path);

// Throws fv::Error naming two of the files when the rig has several cameras and no two of them
// stand apart (1 cm): rays from one place cross nowhere, and every frame would go without a
// position, silently. A rig with one pair apart is left alone.
void CheckRigSpread(const std::vector<camera::Camera>& cameras,
                    const std::vector<std::string>& files);

// The detector options of a tracking camera (`ball`, camera nodes): posed rig cameras, no
// small-ball stage (the tracker's guided fit finds a small ball at its expected size; spots taken
// from the stage moved the low-sun-kick render's centres, mean 3.2 -> 4.1 mm).
detect::BallDetectorOptions TrackingDetectorOptions(double ball_diameter_m,
                                                    const std::string& colour);

// A camera stage's detector from a ball detector: its accepted candidates, then the best few weak
// ones (fusion uses those only to complete a position that an accepted candidate of another
// camera starts).
BallRegionDetectFn BallDetectFnFor(std::shared_ptr<detect::BallDetector> detector);
// The same for the detector chosen by --detector (colour, dnn or both).
BallRegionDetectFn BallDetectFnFor(std::shared_ptr<detect::AnyBallDetector> detector);
// A camera stage's guided fit (detect::BallDetector::FitAt) from a detector.
BallGuidedFn BallGuidedFnFor(std::shared_ptr<detect::BallDetector> detector);
BallGuidedFn BallGuidedFnFor(std::shared_ptr<detect::AnyBallDetector> detector);

}  // namespace fv::pipeline
