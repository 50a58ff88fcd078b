#include "fieldvision/pipeline/frame_sync.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "fieldvision/util/error.h"

namespace fv::pipeline {

void SyncOptions::Check() const {
  FV_REQUIRE(std::isfinite(tolerance_s) && tolerance_s > 0,
             "SyncOptions.tolerance_s must be > 0 (got {})", tolerance_s);
}

int SyncedFrame::present() const {
  return static_cast<int>(
      std::count_if(cameras.begin(), cameras.end(), [](const auto& m) { return m.has_value(); }));
}

int SyncedFrame::SetFrameAndTime() {
  double sum_t = 0;
  int n = 0;
  for (const auto& m : cameras) {
    if (!m) continue;
    sum_t += m->time_s;
    if (n == 0) frame = m->frame;
    ++n;
  }
  time_s = sum_t / n;
  return n;
}

std::string SyncProblemLine(const std::vector<std::string>& names, size_t camera,
                            const std::vector<std::string>& parts) {
  if (parts.empty()) return "";
  return fmt::format("{}: {}",
                     camera < names.size() ? names[camera] : fmt::format("camera {}", camera),
                     fmt::join(parts, ", "));
}

std::vector<std::string> SyncReport::Problems(const std::vector<std::string>& names) const {
  std::vector<std::string> out;
  long long max_last = -1;
  for (const auto& c : cameras) max_last = std::max(max_last, c.last_frame);
  for (size_t i = 0; i < cameras.size(); ++i) {
    const CameraSyncStats& c = cameras[i];
    std::vector<std::string> parts;
    if (c.received == 0) parts.push_back("no frames");
    if (c.gaps > 0) {
      parts.push_back(gaps_are_drops ? fmt::format("{} frames missing (dropped)", c.gaps)
                                     : fmt::format("{} frames without a detection", c.gaps));
    }
    if (c.duplicates > 0) {
      parts.push_back(fmt::format("{} duplicated frames ignored", c.duplicates));
    }
    if (c.out_of_order > 0) {
      parts.push_back(fmt::format("{} out-of-order frames ignored", c.out_of_order));
    }
    if (c.unpaired > 0) parts.push_back(fmt::format("{} frames without a partner", c.unpaired));
    if (c.received > 0 && c.last_frame < max_last) {
      parts.push_back(
          fmt::format("ended at frame {} (others go on to {})", c.last_frame, max_last));
    }
    if (c.first_frame > 0) parts.push_back(fmt::format("starts at frame {}", c.first_frame));
    if (!parts.empty()) out.push_back(SyncProblemLine(names, i, parts));
  }
  return out;
}

FrameSynchronizer::FrameSynchronizer(int num_cameras, const SyncOptions& options)
    : num_cameras_(num_cameras),
      options_(options),
      buffers_(num_cameras),
      last_frame_(num_cameras, -1),
      last_time_(num_cameras, -std::numeric_limits<double>::infinity()) {
  FV_REQUIRE(num_cameras >= 1, "FrameSynchronizer: needs at least one camera");
  options.Check();
  report_.cameras.resize(num_cameras);
}

void FrameSynchronizer::Add(CameraMessage m) {
  FV_REQUIRE(m.camera >= 0 && m.camera < num_cameras_,
             "synchronisation: message for camera {} but there are {} cameras", m.camera,
             num_cameras_);
  FV_REQUIRE(std::isfinite(m.time_s), "synchronisation: camera {} frame {} has a non-finite time",
             m.camera, m.frame);
  const int c = m.camera;
  CameraSyncStats& s = report_.cameras[c];
  FV_REQUIRE(!s.ended, "synchronisation: camera {} sent frame {} after its end", c, m.frame);
  if (last_frame_[c] >= 0) {
    const bool time_mode = options_.mode == SyncMode::kTimestamp;
    if (m.frame == last_frame_[c] || (time_mode && std::abs(m.time_s - last_time_[c]) < 1e-9)) {
      ++s.duplicates;
      return;
    }
    if (m.frame < last_frame_[c] || (time_mode && m.time_s < last_time_[c])) {
      ++s.out_of_order;
      return;
    }
    s.gaps += m.frame - last_frame_[c] - 1;
  } else {
    s.first_frame = m.frame;
  }
  last_frame_[c] = m.frame;
  last_time_[c] = m.time_s;
  s.last_frame = m.frame;
  ++s.received;
  buffers_[c].push_back(std::move(m));
}

void FrameSynchronizer::EndOfStream(int camera) {
  FV_REQUIRE(camera >= 0 && camera < num_cameras_, "synchronisation: no camera {}", camera);
  report_.cameras[camera].ended = true;
}

int FrameSynchronizer::Waiting() const {
  for (int c = 0; c < num_cameras_; ++c) {
    if (!report_.cameras[c].ended && buffers_[c].empty()) return c;
  }
  return -1;
}

bool FrameSynchronizer::Done() const {
  for (int c = 0; c < num_cameras_; ++c) {
    if (!report_.cameras[c].ended || !buffers_[c].empty()) return false;
  }
  return true;
}

std::optional<SyncedFrame> FrameSynchronizer::Next() {
  if (Waiting() >= 0) return std::nullopt;
  // Every live camera has a message waiting: the earliest head decides the group.
  bool any = false;
  long long k = std::numeric_limits<long long>::max();
  double t = std::numeric_limits<double>::infinity();
  for (const auto& b : buffers_) {
    if (b.empty()) continue;
    any = true;
    k = std::min(k, b.front().frame);
    t = std::min(t, b.front().time_s);
  }
  if (!any) return std::nullopt;
  SyncedFrame out;
  out.cameras.resize(num_cameras_);
  for (int c = 0; c < num_cameras_; ++c) {
    auto& b = buffers_[c];
    if (b.empty()) continue;
    const bool take = options_.mode == SyncMode::kFrameIndex
                          ? b.front().frame == k
                          : b.front().time_s - t <= options_.tolerance_s;
    if (!take) continue;
    out.cameras[c] = std::move(b.front());
    b.pop_front();
  }
  const int n = out.SetFrameAndTime();
  ++report_.groups;
  if (n == num_cameras_) ++report_.complete_groups;
  if (n == 1 && num_cameras_ > 1) {
    for (int c = 0; c < num_cameras_; ++c) {
      if (out.cameras[c]) ++report_.cameras[c].unpaired;
    }
  }
  return out;
}

}  // namespace fv::pipeline
