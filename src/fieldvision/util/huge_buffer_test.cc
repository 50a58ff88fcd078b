#include "fieldvision/util/huge_buffer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <utility>

namespace fv::util {
namespace {

// A table's buffer: zero-filled at every size (one byte, a page, more than a huge page), all of
// it writable, and moved rather than copied (the moved-from buffer is empty).
TEST(HugeBuffer, ZeroFilledWritableAndMoved) {
  for (const size_t bytes : {size_t(1), size_t(4096), (size_t(2) << 20) + 17}) {
    HugeBuffer b(bytes);
    ASSERT_NE(b.data(), nullptr);
    EXPECT_EQ(b.size(), bytes);
    size_t nonzero = 0;
    for (size_t i = 0; i < bytes; ++i) nonzero += b[i] != 0;
    EXPECT_EQ(nonzero, 0u) << bytes;
    std::memset(b.data(), 0xAB, bytes);
    HugeBuffer moved(std::move(b));
    EXPECT_EQ(b.data(), nullptr);  // NOLINT(bugprone-use-after-move): the moved-from state
    EXPECT_EQ(b.size(), 0u);       // NOLINT(bugprone-use-after-move)
    EXPECT_EQ(moved[bytes - 1], 0xAB);
    HugeBuffer assigned;
    assigned = std::move(moved);
    EXPECT_EQ(assigned.size(), bytes);
    EXPECT_EQ(assigned[0], 0xAB);
  }
  HugeBuffer empty(0);
  EXPECT_EQ(empty.size(), 0u);
}

}  // namespace
}  // namespace fv::util
