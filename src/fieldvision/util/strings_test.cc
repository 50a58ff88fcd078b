// The stable hash: the published FNV-1a 64-bit test vectors (every compiler and run alike); file
// name parts that are never paths; a byte-order mark skipped.
#include "fieldvision/util/strings.h"

#include <sstream>

#include <gtest/gtest.h>

namespace fv::util {
namespace {

TEST(Strings, ReplaceAllReplacesEveryOccurrenceOnce) {
  EXPECT_EQ(ReplaceAll("a.part a.part", "a.part", "a"), "a a");
  EXPECT_EQ(ReplaceAll("--x{false} --y{true}", "{false}", ""), "--x --y{true}");
  EXPECT_EQ(ReplaceAll("aaa", "a", "aa"), "aaaaaa");  // what comes in is not searched again
  EXPECT_EQ(ReplaceAll("abc", "", "x"), "abc");
}

TEST(Fnv1a64, PublishedVectors) {
  EXPECT_EQ(Fnv1a64(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(Fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(Fnv1a64("foobar"), 0x85944171f73967e8ull);
}

TEST(FileNamePart, KeepsSafeCharactersOnly) {
  EXPECT_EQ(FileNamePart("cam-1_a.b"), "cam-1_a.b");
  EXPECT_EQ(FileNamePart("../a b/c\\d:e"), "___a_b_c_d_e");
  EXPECT_EQ(FileNamePart(".hidden.x"), "_hidden.x");
  EXPECT_EQ(FileNamePart("\u5de6 cam"), "\u5de6_cam");  // a name in another script stays
  EXPECT_EQ(FileNamePart(""), "");
}

// A spreadsheet's UTF-8 byte-order mark before a CSV's header is skipped; other text is read as
// it is, a lone 0xEF byte included.
TEST(WithoutUtf8Bom, DropsAWholeMarkOnly) {
  EXPECT_EQ(WithoutUtf8Bom("\xEF\xBB\xBF"
                           "frame,u"),
            "frame,u");
  EXPECT_EQ(WithoutUtf8Bom("frame,u"), "frame,u");
  EXPECT_EQ(WithoutUtf8Bom("\xEF\xBBx"), "\xEF\xBBx");
  EXPECT_EQ(WithoutUtf8Bom(""), "");
}

TEST(SkipUtf8Bom, SkipsAWholeMarkOnly) {
  std::istringstream with(
      "\xEF\xBB\xBF"
      "frame,u\n");
  SkipUtf8Bom(with);
  std::string line;
  std::getline(with, line);
  EXPECT_EQ(line, "frame,u");
  std::istringstream without("frame,u\n");
  SkipUtf8Bom(without);
  std::getline(without, line);
  EXPECT_EQ(line, "frame,u");
  std::istringstream partial("\xEF\xBBx\n");
  SkipUtf8Bom(partial);
  std::getline(partial, line);
  EXPECT_EQ(line, "\xEF\xBBx");
  std::istringstream empty("");
  SkipUtf8Bom(empty);
  EXPECT_FALSE(std::getline(empty, line));
}

}  // namespace
}  // namespace fv::util
