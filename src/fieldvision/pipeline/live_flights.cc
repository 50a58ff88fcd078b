#include "fieldvision/pipeline/live_flights.h"

#include <algorithm>
#include <cmath>

#include "fieldvision/util/error.h"

namespace fv::pipeline {

void LiveFlightsOptions::Check() const {
  analysis.Check();
  FV_REQUIRE(std::isfinite(analyse_every_s) && analyse_every_s >= 0,
             "LiveFlightsOptions.analyse_every_s must be >= 0 (got {})", analyse_every_s);
  FV_REQUIRE(std::isfinite(track_gap_s) && track_gap_s > 0,
             "LiveFlightsOptions.track_gap_s must be > 0 (got {})", track_gap_s);
  FV_REQUIRE(min_next_samples >= 1, "LiveFlightsOptions.min_next_samples must be >= 1");
  FV_REQUIRE(std::isfinite(max_track_s) && max_track_s > track_gap_s,
             "LiveFlightsOptions.max_track_s must be > track_gap_s (got {})", max_track_s);
}

LiveFlights::LiveFlights(const LiveFlightsOptions& options) : options_(options) { options.Check(); }

std::vector<recon::Flight> LiveFlights::CloseAll() {
  std::vector<recon::Flight> out;
  if (track_.size() >= 3) {
    ++analyses_;
    out = recon::AnalyzeTrajectory(track_, options_.analysis).flights;
  }
  track_.clear();
  return out;
}

std::vector<recon::Flight> LiveFlights::Add(const recon::BallSample& s) {
  std::vector<recon::Flight> out;
  if (!std::isfinite(s.time_s) || !s.ball_in_world.allFinite()) return out;
  if (!track_.empty() && s.time_s <= track_.back().time_s) return out;
  if (!track_.empty() && s.time_s - track_.back().time_s > options_.track_gap_s) out = CloseAll();
  track_.push_back(s);
  while (track_.back().time_s - track_.front().time_s > options_.max_track_s) {
    track_.erase(track_.begin());
  }
  if (s.time_s - last_analysis_s_ < options_.analyse_every_s || track_.size() < 3) return out;
  last_analysis_s_ = s.time_s;
  ++analyses_;
  const recon::TrajectoryResult r = recon::AnalyzeTrajectory(track_, options_.analysis);
  if (r.flights.size() < 2) return out;
  const recon::Flight& open = r.flights.back();
  if (static_cast<int>(open.samples.size()) < options_.min_next_samples) return out;
  out.insert(out.end(), r.flights.begin(), r.flights.end() - 1);
  // The open flight's samples (and whatever follows) stay; the closed ones' leave.
  const int keep_from = *std::min_element(open.samples.begin(), open.samples.end());
  track_.erase(track_.begin(), track_.begin() + keep_from);
  return out;
}

std::vector<recon::Flight> LiveFlights::Finish() { return CloseAll(); }

}  // namespace fv::pipeline
