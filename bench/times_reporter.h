// The benchmarks' console reporter that also keeps each run's adjusted real time by name, for
// the ratios against a baseline run in the same process that every bench prints.
#pragma once

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

namespace fv::bench {

struct TimesReporter : benchmark::ConsoleReporter {
  std::map<std::string, double> times;  // adjusted real time per iteration, in the run's unit
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& r : runs) times[r.benchmark_name()] = r.GetAdjustedRealTime();
    ConsoleReporter::ReportRuns(runs);
  }
  // Prints "ratio NAME Nx <what>" for every run against `baseline` (nothing if it did not run).
  void PrintRatios(const std::string& baseline, const char* what) const {
    const auto base = times.find(baseline);
    if (base == times.end() || base->second <= 0) return;
    for (const auto& [name, t] : times) {
      std::printf("ratio %-28s %8.1fx %s\n", name.c_str(), t / base->second, what);
    }
  }
};

}  // namespace fv::bench
