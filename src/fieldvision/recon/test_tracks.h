// Ball tracks for the trajectory tests: a synth ball's exact centres at each frame plus Gaussian
// noise, as a triangulated track would give them. Used only by *_test.cc.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/synth/ball_physics.h"
#include "fieldvision/util/random.h"

namespace fv::recon::test_util {

// Frames 0..num_frames-1 at time frame / fps; each position noisy by N(0, sigma_m) per axis.
inline std::vector<BallSample> NoisyTrack(const synth::BallTrajectory& trajectory, int num_frames,
                                          double fps, double sigma_m, util::Rng& rng,
                                          int n_cams = 0) {
  std::vector<BallSample> track;
  for (int f = 0; f < num_frames; ++f) {
    BallSample s;
    s.frame = f;
    s.time_s = f / fps;
    s.ball_in_world =
        trajectory.PositionAt(s.time_s) +
        Eigen::Vector3d(rng.Normal(0, sigma_m), rng.Normal(0, sigma_m), rng.Normal(0, sigma_m));
    s.n_cams = n_cams;
    track.push_back(s);
  }
  return track;
}

}  // namespace fv::recon::test_util
