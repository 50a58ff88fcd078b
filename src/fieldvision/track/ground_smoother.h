// Offline smoothing of each track's positions on the field: a constant-velocity Kalman filter
// on the ground plane followed by the Rauch-Tung-Striebel backward pass (Rauch, Tung & Striebel,
// AIAA J. 1965). The measurement noise of a foot point is the ground footprint of a vertical
// pixel error proportional to the box height (detector boxes' bottoms jitter by a few percent of
// the height), so far and grazing views count less. Rows without a measurement (gaps filled by
// interpolation) get the smoothed state.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/track/mot.h"

namespace fv::track {

struct GroundSmoothOptions {
  bool enabled = true;
  double accel_sigma_mps2 = 3.0;  // players' accelerations (white-noise acceleration model)
  double foot_sigma_frac = 0.05;  // vertical foot-point noise as a share of the box height
  double min_sigma_m = 0.03;      // floor of the measurement noise (each axis)
  void Check() const;             // throws fv::Error naming the bad field
};

struct GroundSmoothResult {
  int tracks = 0;             // tracks smoothed
  int measurements = 0;       // rows used as measurements
  int filled = 0;             // rows without a measurement that got the smoothed position
  double mean_shift_m = 0.0;  // mean distance between measured and smoothed positions
  std::string Summary() const;
};

// Smooths x_m, y_m of `rows` per id. `measured[i]` says whether row i is a measurement (false for
// interpolated rows); empty: all rows with a position are. `camera` (calibrated) gives each
// foot point's noise; `fps` the time step.
GroundSmoothResult SmoothGroundTracks(std::vector<TrackRow>& rows,
                                      const std::vector<bool>& measured,
                                      const camera::Camera& camera, double fps,
                                      const GroundSmoothOptions& options = {});

}  // namespace fv::track
