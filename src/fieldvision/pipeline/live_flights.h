// Flights as they close, from a stream of fused ball positions (the fusion node's): the open
// track (positions since the last closed flight) is re-analysed with the offline segmentation
// (recon/trajectory.h, AnalyzeTrajectory) at most every analyse_every_s of ball time; a flight
// is closed once the flight after it has min_next_samples samples (the bounce or hit that ends
// it is then settled) or the track ends (no position for track_gap_s, or the end of the stream).
// Closed flights are handed out once, in time order, and their samples leave the open track.
#pragma once

#include <vector>

#include "fieldvision/recon/trajectory.h"

namespace fv::pipeline {

struct LiveFlightsOptions {
  // The segmentation and fits (spin off: the live analysis runs often; drag auto).
  recon::TrajectoryOptions analysis = [] {
    recon::TrajectoryOptions t;
    t.spin = recon::SpinMode::kOff;
    return t;
  }();
  double analyse_every_s = 0.25;  // of ball time between analyses of the open track
  double track_gap_s = 0.5;       // a gap this long ends the track: its flights all close
  int min_next_samples = 6;       // a flight closes when the next one has this many samples
  double max_track_s = 30;        // the open track keeps at most this much (oldest dropped)
  void Check() const;             // throws fv::Error naming the bad field
};

class LiveFlights {
 public:
  explicit LiveFlights(const LiveFlightsOptions& options);
  // A fused position (time order; earlier ones are ignored); returns the flights it closed.
  std::vector<recon::Flight> Add(const recon::BallSample& sample);
  // The end of the stream: the open track's flights.
  std::vector<recon::Flight> Finish();
  long long analyses() const { return analyses_; }

 private:
  std::vector<recon::Flight> CloseAll();
  LiveFlightsOptions options_;
  std::vector<recon::BallSample> track_;
  double last_analysis_s_ = -1e300;
  long long analyses_ = 0;
};

}  // namespace fv::pipeline
