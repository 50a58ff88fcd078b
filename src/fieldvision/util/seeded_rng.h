// A test's random numbers in one line: util::Rng seeded by testing::TestSeed(fallback) that, while
// it lives, adds the seed to every failure (what TestSeed + FV_SEED_TRACE + Rng(seed) do).
#pragma once

#include <cstdint>
#include <string>

#include <gtest/gtest.h>

#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::testing {

class SeededRng : public util::Rng {
 public:
  explicit SeededRng(uint64_t fallback, const char* file = __builtin_FILE(),
                     int line = __builtin_LINE())
      : util::Rng(TestSeed(fallback)),
        trace_(file, line,
               "seed=" + std::to_string(seed()) +
                   " (rerun with FV_TEST_SEED=" + std::to_string(seed()) + ")") {}

 private:
  ::testing::ScopedTrace trace_;
};

}  // namespace fv::testing
