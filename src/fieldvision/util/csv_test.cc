#include "fieldvision/util/csv.h"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::util {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(Csv, RoundTrip) {
  const std::string path = testing::TempDir() + "/a.csv";
  {
    CsvWriter w(path, {"frame", "x_m", "name"}, 3);
    w << 0 << 1.23456 << "a";
    w.EndRow();
    w << 1 << -2.0 << "b";
    w.EndRow();
    w.Close();
  }
  CsvTable t = CsvTable::Read(path);
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.GetInt(1, "frame"), 1);
  EXPECT_DOUBLE_EQ(t.GetDouble(0, "x_m"), 1.235);
  EXPECT_EQ(t.Get(1, "name"), "b");
}

// Names with commas, quotes or line breaks (a zone "box, left", a player 'Ann "A."') keep every
// row's columns: quoted as RFC 4180 says, read back as written (line breaks as spaces).
TEST(Csv, FieldsWithCommasAndQuotesAreQuoted) {
  const std::string path = testing::TempDir() + "/q.csv";
  {
    CsvWriter w(path, {"frame", "time in box, left", "name"});
    w << 0 << 1.5 << "Ann \"A.\", left";
    w.EndRow();
    w << 1 << 2.0 << "two\nlines";
    w.EndRow();
    w.Close();
  }
  std::ifstream in(path);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "frame,\"time in box, left\",name");
  const CsvTable t = CsvTable::Read(path);
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.Get(0, "name"), "Ann \"A.\", left");
  EXPECT_DOUBLE_EQ(t.GetDouble(0, "time in box, left"), 1.5);
  EXPECT_EQ(t.Get(1, "name"), "two lines");
  EXPECT_THAT([&] { CsvTable::Parse("a,b\n1,\"open\n", "o.csv"); },
              ThrowsMessage<Error>(HasSubstr("o.csv:2: a quoted field is not closed")));
  EXPECT_THAT([&] { CsvTable::Parse("a,b\n1,\"x\"y\n", "t.csv"); },
              ThrowsMessage<Error>(HasSubstr("t.csv:2: text after")));
  EXPECT_EQ(CsvTable::Parse("a, b\n 1 , \" x \"\n", "s.csv").Get(0, "b"), " x ");
  // A first field starting with '#' (a zone "#1 box") is no comment line; edge spaces are kept.
  {
    CsvWriter w(path, {"zone", "t"});
    w << "#1 box"
      << " padded ";
    w.EndRow();
    w.Close();
  }
  const CsvTable hashed = CsvTable::Read(path);
  ASSERT_EQ(hashed.rows(), 1u);
  EXPECT_EQ(hashed.Get(0, "zone"), "#1 box");
  EXPECT_EQ(hashed.Get(0, "t"), " padded ");
}

// A CSV saved by a spreadsheet as "CSV UTF-8" starts with a byte-order mark: the header is read
// without it.
TEST(Csv, AByteOrderMarkBeforeTheHeaderIsSkipped) {
  const CsvTable t = CsvTable::Parse(
      "\xEF\xBB\xBF"
      "frame,time_s\n0,0.5\n",
      "excel.csv");
  ASSERT_TRUE(t.Has("frame"));
  EXPECT_EQ(t.GetDouble(0, "time_s"), 0.5);
}

TEST(Csv, ErrorsNameTheInput) {
  EXPECT_THAT([&] { CsvTable::Read("/nonexistent/x.csv"); },
              ThrowsMessage<Error>(HasSubstr("CSV file '/nonexistent/x.csv' does not exist")));
  // A folder reads as an empty file: "no header" said nothing of what was wrong.
  const std::string folder = testing::TempDir();
  EXPECT_THAT([&] { CsvTable::Read(folder); },
              ThrowsMessage<Error>(HasSubstr("CSV file '" + folder + "' is a folder, not a file")));
  EXPECT_THAT([&] { ReadCsvText(folder, "detections file"); },
              ThrowsMessage<Error>(HasSubstr("detections file '" + folder + "' is a folder")));
  EXPECT_THAT([&] { CsvTable::Parse("a,b\n1,2\n3\n", "f.csv"); },
              ThrowsMessage<Error>(HasSubstr("f.csv:3")));
  CsvTable t = CsvTable::Parse("a,b\n1,x\n", "g.csv");
  EXPECT_THAT([&] { t.GetDouble(0, "b"); }, ThrowsMessage<Error>(HasSubstr("g.csv:2")));
  EXPECT_THROW(t.Require({"a", "c"}), Error);
  EXPECT_THROW(CsvTable::Parse("", "empty.csv"), Error);
}

// A file without header (MOTChallenge's det.txt): the first row takes as many names as it has
// fields, and every other row must have as many.
TEST(Csv, HeaderlessRowsTakeTheirNamesFromTheFirstRow) {
  const std::vector<std::string> names = {"frame", "id", "x", "y"};
  CsvTable t = CsvTable::ParseHeaderless("1,7,0.5\n\n2,8,1.5\n", "det.txt", names);
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.header().size(), 3u);
  EXPECT_FALSE(t.Has("y"));
  EXPECT_EQ(t.GetInt(1, "id"), 8);
  EXPECT_EQ(t.Where(1), "det.txt:3");
  EXPECT_THAT([&] { CsvTable::ParseHeaderless("1,7,0.5\n2,8\n", "r.txt", names); },
              ThrowsMessage<Error>(HasSubstr("r.txt:2: 2 fields, the first row has 3")));
  EXPECT_THAT([&] { CsvTable::ParseHeaderless("1,2,3,4,5\n", "w.txt", names); },
              ThrowsMessage<Error>(HasSubstr("w.txt:1: 5 fields, at most 4 expected")));
  EXPECT_EQ(CsvTable::ParseHeaderless("# nothing\n", "e.txt", names).rows(), 0u);
}

TEST(Csv, WriterRejectsRaggedRows) {
  CsvWriter w(testing::TempDir() + "/b.csv", {"a", "b"});
  w << 1;
  EXPECT_THROW(w.EndRow(), Error);
}

}  // namespace
}  // namespace fv::util
