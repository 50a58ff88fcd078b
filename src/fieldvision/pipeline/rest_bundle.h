// A ball lying still is one point seen in many frames: the runs of a per-frame track where the
// ball rests (its positions within tolerance_m of their mean, a line fitted to them moving less
// than max_drift_m or than its noise) are triangulated once on all the cameras' candidates of those
// frames (each frame's candidate nearest the run's image, within a gate), refitted without the
// candidates it explains far worse than the rest (CandidateOutlierLimitPx), and their rows take
// that point. The frame-to-frame scatter of the centres (sensor noise, JPEG) averages out; what
// every frame shares (a shaded side) stays. Offline, after the flights (BundleFlights).
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/pipeline/camera_message.h"
#include "fieldvision/recon/trajectory.h"

namespace fv::pipeline {

struct RestBundleOptions {
  double tolerance_m = 0.03;  // each position of a run within this of the run's mean
  // The run's fitted line moves less than this over the run (or less than four standard errors
  // of that motion: the positions' own noise).
  double max_drift_m = 0.01;
  // Fewer positions are no run; from this many on a growing run is judged for drift (fewer
  // scatter too little to tell: 3 (n - 2) degrees of freedom). A roll at 0.3 m/s or faster
  // leaves the tolerance before, at 60 fps.
  int min_frames = 12;
  double min_duration_s = 0.1;  // a shorter run is no run
  double max_gap_s = 0.1;       // positions farther apart in time start a new run
  double gate_px = 3.0;         // a candidate farther than this (or half its radius) is no view
  // Of a longer run, this many frames a camera, evenly spread, are triangulated (the views'
  // noise averages out within a few seconds; the triangulation's pairwise checks are quadratic).
  int max_frames_per_camera = 120;
  void Check() const;  // throws fv::Error naming the bad field
};

// Runs [first, last] of track (time order) where the ball rests; rows with skip[i] set (taken by
// a refined flight) belong to none. skip: empty or one per row.
struct RestRun {
  size_t first = 0, last = 0;
};
std::vector<RestRun> FindRestingRuns(const std::vector<recon::BallSample>& track,
                                     const std::vector<char>& skip,
                                     const RestBundleOptions& options);

struct RestBundle {
  int runs = 0;                // runs refined
  long long rows = 0;          // rows given their run's point
  long long observations = 0;  // candidates used
  double rms_px = 0.0;         // their reprojection RMS
  // "N resting balls refined on <views> (R rows, E px RMS)"; "" when no run was refined.
  std::string Summary(const std::string& views) const;
};

// Refines the resting runs of *track in place (ball_radius_m: the triangulation's size checks;
// margin_s: how far from a row's time a candidate may be; messages: per camera, time order).
RestBundle BundleRests(const std::vector<camera::Camera>& cameras,
                       const std::vector<std::vector<CameraMessage>>& messages,
                       double ball_radius_m, double margin_s, const std::vector<char>& skip,
                       const RestBundleOptions& options, std::vector<recon::BallSample>* track);

}  // namespace fv::pipeline
