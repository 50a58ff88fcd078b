// Test helpers: a seed per test (FV_TEST_SEED overrides it) that is printed on failure, a fresh
// temporary folder per test, the path of the shared real data and the message of a thrown error.
#pragma once

#include <cstdint>
#include <exception>
#include <string>

#include <gtest/gtest.h>

namespace fv::testing {

// The test's seed: FV_TEST_SEED if set, else `fallback`. Add FV_SEED_TRACE(seed) after it.
uint64_t TestSeed(uint64_t fallback = 1);
// An empty folder for this test's files (under $FV_TEST_TMP or /tmp).
std::string TempDir();
// ../shared/data next to the source tree; empty string if absent.
std::string SharedDataDir();
// How much slower this build runs than a plain one: 10 under AddressSanitizer (the waiting
// margins of tests that run in real time scale by it), else 1.
double SlowdownFactor();
// What `f` throws (an fv::Error or other std::exception), or "" when it returns.
template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace fv::testing

#define FV_SEED_TRACE(seed)         \
  SCOPED_TRACE(::testing::Message() \
               << "seed=" << (seed) << " (rerun with FV_TEST_SEED=" << (seed) << ")")
