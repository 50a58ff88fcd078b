#include "fieldvision/pipeline/flight_refiner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "fieldvision/util/error.h"

namespace fv::pipeline {
namespace {

// The RMS over every piece's candidates: a piece's (rms_px over n) added to the totals'.
void AddRms(double rms_px, long long n, double* total_rms_px, long long* total_n) {
  const double ss = *total_rms_px * *total_rms_px * static_cast<double>(*total_n) +
                    rms_px * rms_px * static_cast<double>(n);
  *total_n += n;
  *total_rms_px = *total_n > 0 ? std::sqrt(ss / static_cast<double>(*total_n)) : 0.0;
}

}  // namespace

void FlightRefinerOptions::Check() const {
  FV_REQUIRE(std::isfinite(ball_diameter_m) && ball_diameter_m > 0,
             "FlightRefinerOptions.ball_diameter_m must be > 0 (got {})", ball_diameter_m);
  FV_REQUIRE(std::isfinite(ball_mass_kg) && ball_mass_kg >= 0,
             "FlightRefinerOptions.ball_mass_kg must be >= 0 (got {})", ball_mass_kg);
  FV_REQUIRE(std::isfinite(sigma_px) && sigma_px > 0,
             "FlightRefinerOptions.sigma_px must be > 0 (got {})", sigma_px);
  FV_REQUIRE(std::isfinite(gap_s) && gap_s >= recon::TrajectoryOptions().max_gap_s,
             "FlightRefinerOptions.gap_s must be >= the flights' max gap {} s (got {})",
             recon::TrajectoryOptions().max_gap_s, gap_s);
  FV_REQUIRE(std::isfinite(max_piece_s) && max_piece_s > gap_s,
             "FlightRefinerOptions.max_piece_s must be > gap_s (got {})", max_piece_s);
}

FlightRefiner::FlightRefiner(const std::vector<camera::Camera>& cameras,
                             const FlightRefinerOptions& options, RowFn on_row)
    : cameras_(cameras), options_(options), on_row_(std::move(on_row)), messages_(cameras.size()) {
  options_.Check();
  FV_REQUIRE(on_row_ != nullptr, "FlightRefiner: no row callback");
}

void FlightRefiner::AddMessage(CameraMessage message) {
  FV_REQUIRE(message.camera >= 0 && message.camera < static_cast<int>(messages_.size()),
             "FlightRefiner: camera {} of {}", message.camera, messages_.size());
  // Without a position, at most max_piece_s of candidates are held (the fusion may hand out
  // positions a while after it took their candidates off the queues).
  if (track_.empty()) DropBefore(message.time_s - options_.max_piece_s);
  messages_[message.camera].push_back(std::move(message));
}

void FlightRefiner::DropBefore(double time_s) {
  for (auto& m : messages_) {
    m.erase(m.begin(), std::find_if(m.begin(), m.end(),
                                    [&](const CameraMessage& x) { return x.time_s >= time_s; }));
  }
}

void FlightRefiner::AddSample(const recon::BallSample& sample) {
  if (!track_.empty()) {
    FV_REQUIRE(sample.time_s >= track_.back().time_s,
               "FlightRefiner: position at {} s after one at {} s", sample.time_s,
               track_.back().time_s);
    if (sample.time_s - track_.back().time_s > options_.gap_s ||
        sample.time_s - track_.front().time_s > options_.max_piece_s) {
      Flush(sample.time_s);
    }
  }
  // Candidates before a piece's first position (less a gap) belong to none of its flights.
  if (track_.empty()) DropBefore(sample.time_s - options_.gap_s);
  track_.push_back(sample);
}

void FlightRefiner::Finish() { Flush(std::numeric_limits<double>::infinity()); }

long long FlightRefiner::held_messages() const {
  long long n = 0;
  for (const auto& m : messages_) n += static_cast<long long>(m.size());
  return n;
}

// Refines the piece (every position held: all before `before_s`) on the candidates before
// `before_s`, hands its rows out and drops both.
void FlightRefiner::Flush(double before_s) {
  if (track_.empty()) return;
  std::vector<std::vector<CameraMessage>> piece(messages_.size());
  for (size_t c = 0; c < messages_.size(); ++c) {
    auto& m = messages_[c];
    const auto end = std::find_if(m.begin(), m.end(),
                                  [&](const CameraMessage& x) { return x.time_s >= before_s; });
    piece[c].assign(std::make_move_iterator(m.begin()), std::make_move_iterator(end));
    m.erase(m.begin(), end);
  }
  FlightBundle b = BundleFlights(cameras_, piece, options_.ball_diameter_m, options_.ball_mass_kg,
                                 options_.sigma_px, &track_);
  for (const recon::BallSample& s : track_) on_row_(s);
  track_.clear();
  ++pieces_;
  totals_.trajectory = std::move(b.trajectory);
  totals_.bundled_flights += b.bundled_flights;
  totals_.kept_flights += b.kept_flights;
  totals_.bundled_rows += b.bundled_rows;
  totals_.kept_rows += b.kept_rows;
  totals_.rests.runs += b.rests.runs;
  totals_.rests.rows += b.rests.rows;
  AddRms(b.rms_px, b.observations, &totals_.rms_px, &totals_.observations);
  AddRms(b.rests.rms_px, b.rests.observations, &totals_.rests.rms_px, &totals_.rests.observations);
}

}  // namespace fv::pipeline
