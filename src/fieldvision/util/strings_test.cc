// The stable hash: the published FNV-1a 64-bit test vectors (every compiler and run alike); file
// name parts that are never paths.
#include "fieldvision/util/strings.h"

#include <gtest/gtest.h>

namespace fv::util {
namespace {

TEST(Fnv1a64, PublishedVectors) {
  EXPECT_EQ(Fnv1a64(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(Fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(Fnv1a64("foobar"), 0x85944171f73967e8ull);
}

TEST(FileNamePart, KeepsSafeCharactersOnly) {
  EXPECT_EQ(FileNamePart("cam-1_a.b"), "cam-1_a.b");
  EXPECT_EQ(FileNamePart("../a b/c\\d:e"), "___a_b_c_d_e");
  EXPECT_EQ(FileNamePart(".hidden.x"), "_hidden.x");
  EXPECT_EQ(FileNamePart(""), "");
}

}  // namespace
}  // namespace fv::util
