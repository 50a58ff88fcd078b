// A job controller (after COLMAP's controller threads): the caller of a long job (`ball`,
// `node`, `fuse`) gives it a JobControl to receive progress through a callback and to ask it to
// stop; the job checks StopRequested() between frames and returns what it has (a stopped job is
// not an error). The CLI, the fusion node and a web page thus run the same job functions.
#pragma once

#include <atomic>
#include <functional>
#include <mutex>
#include <string>

namespace fv::pipeline {

struct JobProgress {
  std::string job;       // "ball", "node", "fuse"
  long long done = 0;    // units done
  long long total = -1;  // -1: unknown (live input)
  std::string unit;      // "frames"
  std::string status;    // a short line (e.g. cameras connected), may be empty
};

class JobControl {
 public:
  using ProgressFn = std::function<void(const JobProgress&)>;
  JobControl() = default;
  explicit JobControl(ProgressFn on_progress) : on_progress_(std::move(on_progress)) {}
  JobControl(const JobControl&) = delete;
  JobControl& operator=(const JobControl&) = delete;

  // Thread-safe: asks the job to stop at its next check.
  void Stop() { stop_ = true; }
  bool StopRequested() const { return stop_; }
  // Called by the job (any thread; calls are serialised).
  void Report(const JobProgress& progress) {
    if (!on_progress_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    on_progress_(progress);
  }

 private:
  std::atomic<bool> stop_{false};
  ProgressFn on_progress_;
  std::mutex mutex_;
};

// For jobs: true when `control` is given and asks to stop.
inline bool StopRequested(const JobControl* control) {
  return control != nullptr && control->StopRequested();
}

}  // namespace fv::pipeline
