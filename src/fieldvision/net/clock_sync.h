// Clock offset between a camera node and the fusion node, estimated over their connection as NTP
// does (RFC 5905, section 8): the node sends its time t0, the fusion node notes its receipt t1
// and reply t2, the node its receipt t3; offset = ((t1 - t0) + (t2 - t3)) / 2 (fuse - node),
// round trip = (t3 - t0) - (t2 - t1). The estimate is the offset of the shortest round trip among
// the last `window` samples (the least queueing, so the least asymmetry); its error is at most
// half that round trip.
#pragma once

#include <deque>
#include <optional>

namespace fv::net {

struct ClockSample {
  double offset_s = 0;
  double round_trip_s = 0;
};

class ClockSync {
 public:
  explicit ClockSync(int window = 16) : window_(window) {}
  // Adds one exchange; returns false (ignored) when the times are inconsistent.
  bool Add(double t0, double t1, double t2, double t3);
  // The estimate, or nothing before the first sample.
  std::optional<ClockSample> Estimate() const;
  void Reset() { samples_.clear(); }
  int samples() const { return static_cast<int>(samples_.size()); }

 private:
  int window_;
  std::deque<ClockSample> samples_;
};

}  // namespace fv::net
