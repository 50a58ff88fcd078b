#include "fieldvision/net/clock_sync.h"

#include <cmath>

namespace fv::net {

bool ClockSync::Add(double t0, double t1, double t2, double t3) {
  const double round_trip = (t3 - t0) - (t2 - t1);
  if (!(std::isfinite(round_trip) && round_trip >= 0 && t3 >= t0 && t2 >= t1)) return false;
  samples_.push_back({((t1 - t0) + (t2 - t3)) / 2, round_trip});
  while (static_cast<int>(samples_.size()) > window_) samples_.pop_front();
  return true;
}

std::optional<ClockSample> ClockSync::Estimate() const {
  if (samples_.empty()) return std::nullopt;
  const ClockSample* best = &samples_.front();
  for (const ClockSample& s : samples_) {
    if (s.round_trip_s < best->round_trip_s) best = &s;
  }
  return *best;
}

}  // namespace fv::net
