// Prediction and smoothing of ball flights. Landing prediction fits the first part of a flight
// (trajectory.h) and propagates the parameter covariance sigma^2 (J^T J)^-1 to the landing point
// and time by finite differences (first-order error propagation), giving a 95 % ellipse. The
// smoother is a Kalman filter with a Rauch-Tung-Striebel backward pass (Rauch, Tung & Striebel,
// AIAA J. 3(8), 1965) on position and velocity, with gravity inside flights and white-noise
// acceleration, restarted at every bounce, hit and ground phase.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "fieldvision/recon/trajectory.h"

namespace fv::recon {

struct LandingPrediction {
  bool ok = false;
  FlightModel model = FlightModel::kGravity;  // fitted to the samples used
  double fit_rmse_m = 0.0;
  int samples_used = 0;
  double t_cut_s = 0.0;  // samples up to this time were used
  Eigen::Vector3d landing_m = Eigen::Vector3d::Zero();
  double t_landing_s = 0.0;
  Eigen::Matrix2d cov_xy_m2 = Eigen::Matrix2d::Zero();
  double sigma_t_s = 0.0;
  // 95 % ellipse of the landing point: semi-axes and direction of the major axis from +x.
  double semi_major_m = 0.0, semi_minor_m = 0.0, angle_rad = 0.0;
};

// Predicts where the arc through `samples` (the first part of a flight, time order) meets the
// ground. noise_m: the position noise (1 sigma per axis).
LandingPrediction PredictLanding(const std::vector<BallSample>& samples, bool fit_drag,
                                 const TrajectoryOptions& options, double noise_m);
LandingPrediction PredictLanding(const std::vector<BallSample>& samples, FlightModel kind,
                                 const TrajectoryOptions& options, double noise_m);

// The model used to predict a flight's landing from its first samples: the flight's chosen model.
FlightModel PredictionModel(const Flight& flight, const std::vector<BallSample>& samples,
                            const TrajectoryOptions& options, double noise_m);

// Prediction from the samples of `flight` seen before t_start + fraction * flight time.
LandingPrediction PredictFlightLanding(const std::vector<BallSample>& track,
                                       const TrajectoryResult& result, const Flight& flight,
                                       double fraction, const TrajectoryOptions& options);

struct SmootherOptions {
  double accel_noise_mps2 = 3.0;  // white-noise acceleration (1 sigma over 1 s): drag, spin
  double noise_m = 0.0;           // measurement noise; 0: the analysis's estimate
  void Check() const;
};

// Smoothed positions for every sample of the track (outliers get the smoothed estimate); frame,
// time, n_cams and err_px are kept.
std::vector<BallSample> SmoothTrack(const std::vector<BallSample>& track,
                                    const TrajectoryResult& result,
                                    const TrajectoryOptions& options,
                                    const SmootherOptions& smoother);

}  // namespace fv::recon
