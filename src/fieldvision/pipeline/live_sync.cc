#include "fieldvision/pipeline/live_sync.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "fieldvision/util/error.h"

namespace fv::pipeline {

void LiveSyncOptions::Check() const {
  FV_REQUIRE(std::isfinite(tolerance_s) && tolerance_s > 0,
             "LiveSyncOptions.tolerance_s must be > 0 (got {})", tolerance_s);
  FV_REQUIRE(std::isfinite(max_wait_s) && max_wait_s > 0,
             "LiveSyncOptions.max_wait_s must be > 0 (got {})", max_wait_s);
  FV_REQUIRE(max_buffered >= 1, "LiveSyncOptions.max_buffered must be >= 1");
  FV_REQUIRE(std::isfinite(max_time_jump_s) && max_time_jump_s >= 0,
             "LiveSyncOptions.max_time_jump_s must be >= 0 (got {})", max_time_jump_s);
}

namespace {
// Messages in a row in a new time base before a camera is followed there.
constexpr int kConfirmJumpMessages = 3;
}  // namespace

void LiveSynchronizer::SetMaxWait(double max_wait_s) {
  FV_REQUIRE(std::isfinite(max_wait_s) && max_wait_s > 0,
             "LiveSynchronizer: max_wait_s must be > 0 (got {})", max_wait_s);
  options_.max_wait_s = max_wait_s;
}

LiveSynchronizer::LiveSynchronizer(int num_cameras, const LiveSyncOptions& options)
    : n_(num_cameras),
      options_(options),
      buffers_(num_cameras),
      stats_(num_cameras),
      last_frame_(num_cameras, -1),
      last_time_(num_cameras, -std::numeric_limits<double>::infinity()),
      last_arrival_(num_cameras, -std::numeric_limits<double>::infinity()),
      skip_until_s_(num_cameras, -std::numeric_limits<double>::infinity()),
      jump_run_(num_cameras, 0),
      jump_time_s_(num_cameras, 0.0),
      frame_step_s_(num_cameras, 0.0),
      last_frame_arrival_s_(num_cameras, -std::numeric_limits<double>::infinity()) {
  FV_REQUIRE(num_cameras >= 1, "LiveSynchronizer: needs at least one camera");
  options.Check();
}

bool LiveSynchronizer::Add(CameraMessage m, double arrival_s) {
  FV_REQUIRE(m.camera >= 0 && m.camera < n_, "live sync: message for camera {} of {}", m.camera,
             n_);
  const int c = m.camera;
  LiveCameraStats& s = stats_[c];
  s.active = true;
  Heard(c, arrival_s);
  if (!std::isfinite(m.time_s)) {
    ++s.out_of_order;
    return false;
  }
  if (Implausible(c, m.time_s)) {
    ++s.implausible;
    return false;
  }
  if (last_frame_[c] >= 0) {
    if (m.frame == last_frame_[c] || std::abs(m.time_s - last_time_[c]) < 1e-9) {
      ++s.duplicates;
      return false;
    }
    if (m.frame < last_frame_[c] || m.time_s < last_time_[c]) {
      ++s.out_of_order;
      return false;
    }
    s.gaps += m.frame - last_frame_[c] - 1;
  }
  if (last_frame_[c] >= 0 && m.frame > last_frame_[c]) {
    const double step = (m.time_s - last_time_[c]) / static_cast<double>(m.frame - last_frame_[c]);
    frame_step_s_[c] = frame_step_s_[c] > 0 ? 0.9 * frame_step_s_[c] + 0.1 * step : step;
  }
  last_frame_[c] = m.frame;
  last_time_[c] = m.time_s;
  if (any_group_ && m.time_s <= decided_until_s_) {
    ++s.late;
    return false;
  }
  ++s.received;
  last_frame_arrival_s_[c] = arrival_s;
  if (buffers_[c].size() >= options_.max_buffered) {
    buffers_[c].pop_front();
    ++s.overflow;
  }
  buffers_[c].push_back({std::move(m), arrival_s});
  return true;
}

bool LiveSynchronizer::Implausible(int c, double time_s) {
  const double jump = options_.max_time_jump_s;
  if (jump <= 0) return false;
  // Its stream: its last frame, or where it said its source skipped to (SkipUntil).
  double reference = std::max(last_time_[c], skip_until_s_[c]);
  if (last_frame_[c] < 0) {  // its first message: the latest of the other active cameras, if any
    reference = -std::numeric_limits<double>::infinity();
    for (int o = 0; o < n_; ++o) {
      if (o != c && stats_[o].active && last_frame_[o] >= 0) {
        reference = std::max(reference, last_time_[o]);
      }
    }
  }
  if (!std::isfinite(reference) || std::abs(time_s - reference) <= jump) {
    jump_run_[c] = 0;
    return false;
  }
  jump_run_[c] =
      jump_run_[c] > 0 && std::abs(time_s - jump_time_s_[c]) <= jump ? jump_run_[c] + 1 : 1;
  jump_time_s_[c] = time_s;
  if (jump_run_[c] < kConfirmJumpMessages) return true;
  // The camera goes on there: follow it. Groups decided past it are forgotten only when the
  // other active cameras are there too (the clock they share was stepped back); one camera alone
  // in another time base is left to be late, as before, rather than reopen decided times.
  jump_run_[c] = 0;
  last_frame_[c] = -1;
  last_time_[c] = -std::numeric_limits<double>::infinity();
  // Its frames still held from the time base it left (a glitch it comes back from) would stand
  // before the new ones for good.
  auto& held = buffers_[c];
  const auto left = std::remove_if(held.begin(), held.end(), [&](const Held& h) {
    return std::abs(h.message.time_s - time_s) > jump;
  });
  stats_[c].implausible += held.end() - left;
  stats_[c].received -= held.end() - left;
  held.erase(left, held.end());
  skip_until_s_[c] = -std::numeric_limits<double>::infinity();
  bool rig_moved = true;
  for (int o = 0; o < n_; ++o) {
    if (o != c && stats_[o].active && last_frame_[o] >= 0) {
      rig_moved = rig_moved && std::abs(last_time_[o] - time_s) <= jump;
    }
  }
  if (rig_moved && decided_until_s_ > time_s) decided_until_s_ = time_s - options_.tolerance_s;
  return false;
}

void LiveSynchronizer::NumberInStream(SyncedFrame& out) {
  // The reference: the camera with the most frames per second (the lowest index among equals).
  int ref = -1;
  for (int c = 0; c < n_; ++c) {
    if (frame_step_s_[c] > 0 && (ref < 0 || frame_step_s_[c] < 0.9 * frame_step_s_[ref])) ref = c;
  }
  if (ref >= 0 && out.cameras[ref]) {
    out.frame = out.cameras[ref]->frame;
  } else if (ref >= 0 && last_frame_[ref] >= 0) {
    out.frame =
        last_frame_[ref] + std::llround((out.time_s - last_time_[ref]) / frame_step_s_[ref]);
  }
  if (numbered_ && out.frame <= last_out_frame_) out.frame = last_out_frame_ + 1;
  numbered_ = true;
  last_out_frame_ = out.frame;
}

void LiveSynchronizer::SetFrameRate(int camera, double fps) {
  FV_REQUIRE(camera >= 0 && camera < n_, "live sync: no camera {}", camera);
  // Until its frames tell (a source's stated rate may be off; hellos come with every ping).
  if (frame_step_s_[camera] > 0) return;
  if (std::isfinite(fps) && fps > 0 && fps < 1e4) frame_step_s_[camera] = 1.0 / fps;
}

void LiveSynchronizer::Admit(int camera, double arrival_s) {
  FV_REQUIRE(camera >= 0 && camera < n_, "live sync: no camera {}", camera);
  stats_[camera].active = true;
  Heard(camera, arrival_s);
}

void LiveSynchronizer::SkipUntil(int camera, double time_s, double arrival_s) {
  FV_REQUIRE(camera >= 0 && camera < n_, "live sync: no camera {}", camera);
  if (!std::isfinite(time_s)) return;
  skip_until_s_[camera] = std::max(skip_until_s_[camera], time_s);
  stats_[camera].active = true;
  Heard(camera, arrival_s);
}

void LiveSynchronizer::Heard(int camera, double arrival_s) {
  last_arrival_[camera] = std::max(last_arrival_[camera], arrival_s);
  first_arrival_s_ = std::min(first_arrival_s_, arrival_s);
}

bool LiveSynchronizer::WaitFor(int camera, double now_s) const {
  // A camera never heard from is expected: it is waited for as if heard when the first camera
  // was (nodes connect one after another).
  const bool never_heard = !std::isfinite(last_arrival_[camera]);
  const double heard_s = never_heard ? first_arrival_s_ : last_arrival_[camera];
  return (stats_[camera].active || never_heard) && now_s - heard_s < options_.max_wait_s;
}

bool LiveSynchronizer::FarAheadOfALiveCamera(double time_s, double now_s) const {
  if (options_.max_time_jump_s <= 0) return false;
  for (int c = 0; c < n_; ++c) {
    // Only a camera still delivering frames that count holds it (not one that only answers
    // clock pings while its source is stuck, nor one whose frames are all late).
    const bool delivering = now_s - last_frame_arrival_s_[c] < options_.max_wait_s;
    if (stats_[c].active && delivering && std::isfinite(last_time_[c]) &&
        time_s - last_time_[c] > options_.max_time_jump_s) {
      return true;
    }
  }
  return false;
}

void LiveSynchronizer::Restart(int camera) {
  FV_REQUIRE(camera >= 0 && camera < n_, "live sync: no camera {}", camera);
  skip_until_s_[camera] = -std::numeric_limits<double>::infinity();
  ++stats_[camera].restarts;
  last_frame_[camera] = -1;
  last_time_[camera] = -std::numeric_limits<double>::infinity();
}

void LiveSynchronizer::EndOfStream(int camera) {
  FV_REQUIRE(camera >= 0 && camera < n_, "live sync: no camera {}", camera);
  stats_[camera].active = false;
}

bool LiveSynchronizer::Empty() const {
  return std::all_of(buffers_.begin(), buffers_.end(), [](const auto& b) { return b.empty(); });
}

std::optional<SyncedFrame> LiveSynchronizer::Next(double now_s, bool flush) {
  double t = std::numeric_limits<double>::infinity();
  for (const auto& b : buffers_) {
    if (!b.empty()) t = std::min(t, b.front().message.time_s);
  }
  if (!std::isfinite(t)) return std::nullopt;
  const double until = t + options_.tolerance_s;
  // The group's members and its first arrival.
  double first_arrival = std::numeric_limits<double>::infinity();
  bool ready = true;
  for (int c = 0; c < n_; ++c) {
    const auto& b = buffers_[c];
    if (!b.empty() && b.front().message.time_s <= until) {
      first_arrival = std::min(first_arrival, b.front().arrival_s);
      continue;
    }
    if (!b.empty()) continue;                // it has sent something later: not in this group
    if (skip_until_s_[c] > until) continue;  // it skipped this group's frames
    // Nothing from camera c: wait for it only when it is active and not silent for long.
    if (WaitFor(c, now_s)) ready = false;
  }
  if (!ready && !flush && now_s - first_arrival < options_.max_wait_s) return std::nullopt;
  // A camera followed into a time base far ahead of the others' (max_time_jump_s) would decide
  // that time for every camera, and the others' frames would all be late: it waits while they go
  // on.
  if (!flush && FarAheadOfALiveCamera(t, now_s)) return std::nullopt;
  SyncedFrame out;
  out.cameras.resize(n_);
  for (int c = 0; c < n_; ++c) {
    auto& b = buffers_[c];
    if (b.empty() || b.front().message.time_s > until) continue;
    out.cameras[c] = std::move(b.front().message);
    b.pop_front();
  }
  const int k = out.SetFrameAndTime();
  NumberInStream(out);
  any_group_ = true;
  decided_until_s_ = std::max(decided_until_s_, until);
  ++groups_;
  if (k == n_) ++complete_groups_;
  for (int c = 0; c < n_; ++c) {
    if (out.cameras[c]) ++(k > 1 ? stats_[c].paired : stats_[c].unpaired);
  }
  return out;
}

std::vector<std::string> LiveSynchronizer::Problems(const std::vector<std::string>& names) const {
  std::vector<std::string> out;
  for (int c = 0; c < n_; ++c) {
    const LiveCameraStats& s = stats_[c];
    std::vector<std::string> parts;
    if (s.received == 0) parts.push_back("no frames");
    if (s.gaps > 0) parts.push_back(fmt::format("{} frames missing (dropped)", s.gaps));
    if (s.late > 0) parts.push_back(fmt::format("{} late frames dropped", s.late));
    if (s.duplicates > 0) parts.push_back(fmt::format("{} duplicates dropped", s.duplicates));
    if (s.out_of_order > 0) {
      parts.push_back(fmt::format("{} out-of-order frames dropped", s.out_of_order));
    }
    if (s.overflow > 0) parts.push_back(fmt::format("{} dropped (buffer full)", s.overflow));
    if (s.unpaired > 0) parts.push_back(fmt::format("{} frames without a partner", s.unpaired));
    if (s.restarts > 0) parts.push_back(fmt::format("restarted {} times", s.restarts));
    if (s.implausible > 0) {
      parts.push_back(fmt::format("{} frames dropped for a time over {:g} s from the stream's",
                                  s.implausible, options_.max_time_jump_s));
    }
    if (!parts.empty()) out.push_back(SyncProblemLine(names, static_cast<size_t>(c), parts));
  }
  return out;
}

}  // namespace fv::pipeline
