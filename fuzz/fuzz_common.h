// Shared by the libFuzzer harnesses (fuzz/*_fuzz.cc): the input written to a file when a reader
// takes a path, and the rule every harness checks: bad input is an fv::Error (one line naming the
// input); any other exception, a crash or a sanitizer report is a finding.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "fieldvision/util/error.h"

namespace fv::fuzz {

// A folder of this process's own (removed at exit), for inputs that readers take as files.
inline const std::filesystem::path& ScratchDir() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() /
             ("fv-fuzz-" + std::to_string(static_cast<long>(getpid())));
    std::filesystem::create_directories(d);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(std::filesystem::temp_directory_path() /
                                      ("fv-fuzz-" + std::to_string(static_cast<long>(getpid()))),
                                  ec);
    });
    return d;
  }();
  return dir;
}

// Writes `data` to ScratchDir()/name and returns its path.
inline std::string WriteInput(std::string_view data, const std::string& name) {
  const auto path = ScratchDir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  return path.string();
}

// The message must be one line (CONTRACT: one stderr line per error).
inline void CheckOneLine(const char* what) {
  if (std::string_view(what).find('\n') != std::string_view::npos) {
    std::fprintf(stderr, "fuzz: fv::Error message of more than one line: %s\n", what);
    std::abort();
  }
}

// Runs `f`; fv::Error is the expected answer to bad input, anything else aborts (a finding).
template <typename F>
void ExpectErrorOrValue(F&& f) {
  try {
    f();
  } catch (const fv::Error& e) {
    CheckOneLine(e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: exception that is not an fv::Error: %s\n", e.what());
    std::abort();
  }
}

}  // namespace fv::fuzz
