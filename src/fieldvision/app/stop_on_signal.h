// Ctrl-C and SIGTERM ask a long-running command's job (`node`, `fuse`) to stop through its
// JobControl (pipeline/job.h), which then returns what it has; while no StopOnSignal lives the
// handlers do nothing.
#pragma once

#include <atomic>
#include <csignal>

#include "fieldvision/pipeline/job.h"

namespace fv::app {

class StopOnSignal {
 public:
  explicit StopOnSignal(pipeline::JobControl& control) {
    target_ = &control;
    std::signal(SIGINT, &Handle);
    std::signal(SIGTERM, &Handle);
  }
  ~StopOnSignal() { target_ = nullptr; }
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;

 private:
  static void Handle(int) {
    pipeline::JobControl* control = target_;
    if (control != nullptr) control->Stop();
  }
  static inline std::atomic<pipeline::JobControl*> target_{nullptr};
};

}  // namespace fv::app
