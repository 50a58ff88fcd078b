// Offline flight refinement in bounded memory: fused positions and the cameras' accepted
// candidates are held only for the current piece of the track, cut where no position came for
// longer than a flight may go unseen (recon::TrajectoryOptions::max_gap_s, so no flight spans a
// cut) or, for a ball seen without such a gap, after max_piece_s; each piece's flights are
// refined on the candidates (BundleFlights, detections_job.h) and its rows handed out, in time
// order, then its candidates are dropped.
#pragma once

#include <functional>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/pipeline/detections_job.h"

namespace fv::pipeline {

struct FlightRefinerOptions {
  double ball_diameter_m = 0.22;
  double ball_mass_kg = 0.0;   // 0: from the diameter (detections_job.h)
  double sigma_px = 2.0;       // 1-sigma of a candidate's centre
  double gap_s = 0.5;          // no position for longer cuts the track (>= the flights' max gap)
  double max_piece_s = 120.0;  // a piece of track is cut after this long anyway
  void Check() const;          // throws fv::Error naming the bad field
};

class FlightRefiner {
 public:
  using RowFn = std::function<void(const recon::BallSample&)>;
  FlightRefiner(const std::vector<camera::Camera>& cameras, const FlightRefinerOptions& options,
                RowFn on_row);
  // A camera's accepted candidates of one frame (each camera's in time order).
  void AddMessage(CameraMessage message);
  // A fused position, in time order.
  void AddSample(const recon::BallSample& sample);
  // The end of the track: the last piece is refined and handed out.
  void Finish();
  // Over all pieces so far (trajectory: the last piece's analysis).
  const FlightBundle& totals() const { return totals_; }
  long long pieces() const { return pieces_; }
  // Candidates and positions held now (the current piece).
  long long held_messages() const;
  long long held_samples() const { return static_cast<long long>(track_.size()); }

 private:
  void Flush(double before_s);
  void DropBefore(double time_s);  // every camera's candidates before time_s
  std::vector<camera::Camera> cameras_;
  FlightRefinerOptions options_;
  RowFn on_row_;
  std::vector<std::vector<CameraMessage>> messages_;  // per camera
  std::vector<recon::BallSample> track_;
  FlightBundle totals_;
  long long pieces_ = 0;
};

}  // namespace fv::pipeline
