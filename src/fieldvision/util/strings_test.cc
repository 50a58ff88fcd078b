// The stable hash: the published FNV-1a 64-bit test vectors (every compiler and run alike).
#include "fieldvision/util/strings.h"

#include <gtest/gtest.h>

namespace fv::util {
namespace {

TEST(Fnv1a64, PublishedVectors) {
  EXPECT_EQ(Fnv1a64(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(Fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(Fnv1a64("foobar"), 0x85944171f73967e8ull);
}

}  // namespace
}  // namespace fv::util
