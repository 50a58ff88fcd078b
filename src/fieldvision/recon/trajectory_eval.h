// Scores the flight models on real tracks with one bounce each (TT3D table tennis, or any track
// read by trajectory_io.h): residual of each model on the flight before the bounce, and the
// landing predicted from the first half of that flight against the bounce point measured from
// the full track (a free constant-acceleration fit of the last reference_window_s before the
// contact, crossing the bounce height; a few millimetres of extrapolation at 180 Hz).
#pragma once

#include <string>
#include <vector>

#include "fieldvision/recon/trajectory.h"

namespace fv::recon {

struct BounceTrackScore {
  std::string path;
  int bounces = 0, hits = 0, flights = 0, outliers = 0;
  bool scored = false;  // a flight ending in a bounce was found and fitted
  std::string model;    // chosen for the pre-bounce flight
  // Pre-bounce flight residuals (metres; NaN when not fitted).
  double rmse_gravity_m = 0, rmse_drag_m = 0, rmse_spin_m = 0, rmse_free_m = 0, rmse_chosen_m = 0;
  double spin_revps = 0;
  // Landing from the first half of the pre-bounce flight: horizontal error to the reference
  // bounce point (NaN when the prediction failed).
  double pred_chosen_m = 0, pred_drag_m = 0, pred_spin_m = 0, pred_free_m = 0;
  // The flight after the bounce predicted from the whole flight before it through the bounce
  // model (trajectory.h, BounceOptions): RMS position error over its first 0.1 s (NaN if none).
  double after_bounce_rmse_m = 0;
  // The bounce measured from the fitted arcs on both sides (trajectory.h, BounceFit; NaN if not).
  double restitution = 0, friction = 0;
};

struct BounceTrackSummary {
  std::vector<BounceTrackScore> tracks;
  // Medians over the scored tracks.
  double median_rmse_gravity_m = 0, median_rmse_drag_m = 0, median_rmse_spin_m = 0,
         median_rmse_free_m = 0, median_rmse_chosen_m = 0;
  double median_pred_chosen_m = 0, median_pred_drag_m = 0, median_pred_spin_m = 0,
         median_pred_free_m = 0;
  double median_after_bounce_rmse_m = 0;
  double median_restitution = 0, median_friction = 0;
  int one_bounce = 0;         // tracks with exactly one bounce
  int spin_chosen = 0;        // pre-bounce flights where the spin model was chosen
  std::string Table() const;  // one row per track and the medians
};

struct BounceEvalOptions {
  double prediction_fraction = 0.5;  // of the seen span before the bounce
  double reference_window_s = 0.06;  // samples before the contact used for the reference
  void Check() const;
};

BounceTrackScore ScoreBounceTrack(const std::string& path, const std::vector<BallSample>& track,
                                  const TrajectoryOptions& options,
                                  const BounceEvalOptions& eval = {});
BounceTrackSummary Summarize(std::vector<BounceTrackScore> tracks);

}  // namespace fv::recon
