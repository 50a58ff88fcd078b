#include "fieldvision/util/parallel.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <vector>

#include "fieldvision/util/error.h"

namespace fv::util {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(ParallelFor, EveryIndexOnce) {
  for (size_t n : {0, 1, 3, 257}) {
    std::vector<std::atomic<int>> calls(n);
    ParallelFor(n, [&](size_t i) { ++calls[i]; });
    for (size_t i = 0; i < n; ++i) EXPECT_EQ(calls[i].load(), 1) << "n " << n << " index " << i;
  }
}

TEST(ParallelFor, FirstErrorIsRethrown) {
  std::atomic<int> done{0};
  EXPECT_THAT(
      [&] {
        ParallelFor(100, [&](size_t i) {
          if (i == 7) Throw("index {} failed", i);
          ++done;
        });
      },
      ThrowsMessage<Error>(HasSubstr("index 7 failed")));
  EXPECT_LT(done.load(), 100);
}

}  // namespace
}  // namespace fv::util
