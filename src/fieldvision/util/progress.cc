#include "fieldvision/util/progress.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <fmt/format.h>

namespace fv::util {

Progress::Progress(std::string label, long long total, std::string unit, bool enabled)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      enabled_(enabled),
      tty_(isatty(STDERR_FILENO) != 0),
      lines_(!tty_ && std::getenv(kProgressEnv) != nullptr &&
             std::strcmp(std::getenv(kProgressEnv), kProgressLines) == 0),
      start_(std::chrono::steady_clock::now()),
      last_print_(start_) {}

Progress::~Progress() {
  if (!finished_ && done_ > 0) Finish();
}

double Progress::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::Update(long long done) {
  done_ = done;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (tty_) {
    if (now - last_print_ < std::chrono::milliseconds(200)) return;
    last_print_ = now;
    Print(false);
  } else if (lines_ && total_ > 0) {
    const int decile = static_cast<int>(10 * done_ / total_);
    if (decile > last_decile_ && decile < 10) {
      last_decile_ = decile;
      Print(false);
    }
  }
}

void Progress::Print(bool final_line) {
  const double t = ElapsedSeconds();
  const double rate = t > 0 ? static_cast<double>(done_) / t : 0.0;
  std::string line;
  if (total_ > 0) {
    const double left = rate > 0 ? static_cast<double>(total_ - done_) / rate : 0.0;
    line = fmt::format("{}: {}/{} {} ({:.0f}%), {:.1f} {}/s, {:.1f} s elapsed, {:.1f} s left",
                       label_, done_, total_, unit_, 100.0 * done_ / total_, rate, unit_, t,
                       final_line ? 0.0 : left);
  } else {
    line = fmt::format("{}: {} {}, {:.1f} {}/s, {:.1f} s elapsed", label_, done_, unit_, rate,
                       unit_, t);
  }
  if (tty_) {
    std::fprintf(stderr, "\r\033[K%s%s", line.c_str(), final_line ? "\n" : "");
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
  std::fflush(stderr);
}

void Progress::Finish() {
  finished_ = true;
  if (enabled_ && (tty_ || lines_)) Print(true);
}

}  // namespace fv::util
