// Progress of a long job on stderr: items done, rate and time left. On a terminal it redraws one
// line; elsewhere (a log) it stays quiet, unless the environment asks for lines (kLinesEnv=lines:
// a line every ~10 % and a last one, as the studio's jobs page reads them).
#pragma once

#include <chrono>
#include <string>

namespace fv::util {

// The environment variable, and its value, that asks for progress lines off a terminal.
inline constexpr const char* kProgressEnv = "FV_PROGRESS";
inline constexpr const char* kProgressLines = "lines";

class Progress {
 public:
  // total <= 0 means unknown. `unit` names the items ("frames").
  Progress(std::string label, long long total, std::string unit = "frames", bool enabled = true);
  ~Progress();
  void Update(long long done);
  void Finish();
  double ElapsedSeconds() const;

 private:
  void Print(bool final_line);
  std::string label_;
  std::string unit_;
  long long total_;
  long long done_ = 0;
  bool enabled_;
  bool tty_;
  bool lines_;  // off a terminal, lines asked for (kProgressEnv)
  bool finished_ = false;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_print_;
};

}  // namespace fv::util
