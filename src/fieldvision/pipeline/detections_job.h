// `fieldvision ball --detections`: the ball in 3D from 2D detections made by another tool
// (TrackNet and the like) instead of videos. Each camera's DET.csv (`frame,time_s,u,v`, optional
// `radius_px`, `score`; several rows of one frame are candidates, empty u/v a frame without any)
// becomes timestamped camera messages, paired by capture time as videos are (frame_sync.h),
// fused robustly per frame (the pipeline's FuseFrame: every two-view hypothesis over the
// candidates, Fischler & Bolles 1981) and split into flights (recon/trajectory.h). Then a
// physics-constrained bundle: per flight, the flight model (gravity, drag, spin as chosen) is
// fitted to the 2D detections of all cameras at their own capture times (reprojection error,
// Huber loss; Ceres), and the positions inside the flight are taken from it. Written as BALL.csv
// (and FLIGHTS.json when asked).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "fieldvision/pipeline/camera_message.h"
#include "fieldvision/pipeline/frame_sync.h"
#include "fieldvision/pipeline/rest_bundle.h"
#include "fieldvision/recon/ball_eval.h"
#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/triangulation.h"

namespace fv::pipeline {

struct DetectionsJobOptions {
  std::vector<std::string> cameras;     // camera files, paired with `detections` in order
  std::vector<std::string> detections;  // DET.csv per camera
  double ball_diameter_m = 0.22;
  double sigma_px = 2.0;       // 1-sigma of a detection's centre (pixels)
  double tolerance_s = 0.008;  // detections this close in time are one moment
  std::string out;             // BALL.csv
  std::string truth;           // optional truth.csv for the error table
  std::string flights;         // optional FLIGHTS.json: the trajectory fit of the result
  bool bundle = true;          // refine flights on the 2D detections (else per-frame points)
  double ball_mass_kg = 0.0;   // for the spin model; 0: recon::NearestStandardBall's
  recon::TriangulationOptions triangulation;  // ball_radius_m is set from the diameter
  // Whether the detections' scores are fieldvision's own (`ball --write-detections`),
  // so that triangulation.min_two_view_score applies; scores made elsewhere have no known scale
  // and it is not used.
  bool own_scores = false;
  recon::BallEvalOptions eval;
  void Check() const;  // throws fv::Error naming the bad option
};

struct DetectionsJobResult {
  long long frames = 0;      // synchronised moments
  long long positions = 0;   // rows written
  long long candidates = 0;  // detection rows read (all cameras)
  SyncReport sync;
  std::vector<std::string> camera_names;     // the camera files' names, for the summary
  std::vector<recon::BallSample> track;      // what BALL.csv holds
  std::vector<recon::BallSample> per_frame;  // the per-frame triangulation (before the bundle)
  int bundled_flights = 0;                   // flights refined on the 2D detections
  long long bundled_rows = 0;                // rows of BALL.csv taken from them
  long long kept_rows = 0;     // rows inside them that kept their own position (BundleFlights)
  double bundle_rms_px = 0.0;  // reprojection RMS of the bundled detections
  RestBundle rests;            // resting runs refined (BundleFlights)
  std::optional<recon::BallEvalResult> eval;          // with a truth file
  std::optional<recon::TrajectoryResult> trajectory;  // with `flights`
  std::string Summary() const;
};

// Reads one camera's DET.csv as messages in time order (camera index `camera`). Throws fv::Error
// naming the file (and line) for a missing column, a non-finite value, a frame whose rows
// disagree on the time, or times that do not increase from frame to frame.
std::vector<CameraMessage> ReadDetectionsCsv(const std::string& path, int camera,
                                             double sigma_px = 2.0);
std::vector<CameraMessage> ParseDetections(const util::CsvTable& table, int camera,
                                           double sigma_px);

DetectionsJobResult RunDetectionsJob(const DetectionsJobOptions& options);

// Candidates farther than this from a refined model's image are left out of the refit: four
// times the robust spread of the distances (their median over the Rayleigh median, 1.1774
// sigma), at least 0.5 px.
double CandidateOutlierLimitPx(const std::vector<double>& dist_px);

// The flights of a per-frame track (time order), each refined on the cameras' candidates
// (`messages`: per camera, in time order) by the physics-constrained bundle above; the track's
// positions inside a refined flight become the flight model's (err_px: the flight's RMS), unless
// the model explains the candidates much worse than the per-frame positions do (not a free
// flight: a carried or deflected ball) or lies far from most of them (a "flight" between two
// places where the ball rested), which are then kept; so is a single frame whose candidates the
// model explains much worse than its typical frame's and than the frame's own position. Then the
// rows outside refined flights where the ball rests take their run's point (BundleRests).
struct FlightBundle {
  std::optional<recon::TrajectoryResult> trajectory;
  int bundled_flights = 0;
  int kept_flights = 0;  // flights whose per-frame positions were kept
  long long bundled_rows = 0;
  long long kept_rows = 0;     // rows inside refined flights that kept their own position
  double rms_px = 0.0;         // reprojection RMS of the candidates used
  long long observations = 0;  // candidates used
  RestBundle rests;            // then the runs where the ball rests (rest_bundle.h)
};
FlightBundle BundleFlights(const std::vector<camera::Camera>& cameras,
                           const std::vector<std::vector<CameraMessage>>& messages,
                           double ball_diameter_m, double ball_mass_kg, double sigma_px,
                           std::vector<recon::BallSample>* track);

}  // namespace fv::pipeline
