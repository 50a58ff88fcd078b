// Ctrl-C and SIGTERM ask a long-running command's job (`node`, `fuse`) to stop through its
// JobControl (pipeline/job.h), which then returns what it has; a second one ends the process at
// once (a source blocked in a read, e.g. a silent stream, never sees the stop). While no
// StopOnSignal lives the handlers do nothing.
#pragma once

#include <unistd.h>

#include <atomic>
#include <csignal>

#include "fieldvision/pipeline/job.h"

namespace fv::app {

class StopOnSignal {
 public:
  explicit StopOnSignal(pipeline::JobControl& control) {
    target_ = &control;
    terminal_ = isatty(STDERR_FILENO) == 1;  // decided here: isatty is not async-signal-safe
    std::signal(SIGINT, &Handle);
    std::signal(SIGTERM, &Handle);
  }
  ~StopOnSignal() { target_ = nullptr; }
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;

 private:
  static void Handle(int sig) {
    pipeline::JobControl* control = target_;
    if (control == nullptr) return;
    if (stopping_.exchange(true)) {  // the second: the default action (the process ends)
      std::signal(sig, SIG_DFL);
      std::raise(sig);
      return;
    }
    control->Stop();
    // On a terminal the progress line may be half written: the message starts a line of its own.
    constexpr char kSaid[] = "\nstopping (again to quit at once, outputs unwritten)\n";
    const int skip = terminal_ ? 0 : 1;
    [[maybe_unused]] const ssize_t n = write(STDERR_FILENO, kSaid + skip, sizeof(kSaid) - 1 - skip);
  }
  static inline std::atomic<pipeline::JobControl*> target_{nullptr};
  static inline std::atomic<bool> stopping_{false};
  static inline std::atomic<bool> terminal_{false};
};

}  // namespace fv::app
