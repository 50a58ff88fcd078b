#include "fieldvision/util/json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::util {
namespace {

using nlohmann::json;
using testing::ErrorOf;

void ExpectNames(const std::string& error, std::initializer_list<const char*> parts) {
  EXPECT_FALSE(error.empty());
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  for (const char* p : parts) EXPECT_NE(error.find(p), std::string::npos) << p << " in " << error;
}

TEST(Json, ReadersReturnValuesAndFallbacks) {
  const json o = {{"x", 2.5}, {"n", 7}, {"b", true}, {"s", "hi"}, {"v", {1, 2, 3}}};
  EXPECT_DOUBLE_EQ(JsonNumber(o, "x", "f"), 2.5);
  EXPECT_DOUBLE_EQ(JsonNumber(o, "n", "f"), 7.0);
  EXPECT_DOUBLE_EQ(JsonNumber(o, "missing", "f", 4.0), 4.0);
  EXPECT_EQ(JsonInt(o, "n", "f"), 7);
  EXPECT_EQ(JsonInt(o, "missing", "f", -1), -1);
  EXPECT_EQ(JsonInt64(json{{"t", 1LL << 40}}, "t", "f"), 1LL << 40);
  EXPECT_EQ(JsonInt64(o, "missing", "f", -2), -2);
  EXPECT_TRUE(JsonBool(o, "b", "f"));
  EXPECT_EQ(JsonString(o, "s", "f"), "hi");
  EXPECT_EQ(JsonString(o, "missing", "f", "dflt"), "dflt");
  EXPECT_EQ(JsonNumbers(o, "v", "f"), (std::vector<double>{1, 2, 3}));
  EXPECT_TRUE(JsonNumbers(o, "missing", "f", false).empty());
  EXPECT_EQ(JsonVector<3>(o, "v", "f"), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(JsonVector<2>(o, "missing", "f", Eigen::Vector2d(5, 6)), Eigen::Vector2d(5, 6));
  EXPECT_TRUE(JsonArray(o, "missing", "f").empty());
  EXPECT_TRUE(JsonObject(o, "missing", "f").is_object());
  EXPECT_EQ(JsonPath("", "a"), "a");
  EXPECT_EQ(JsonPath("ball.kicks[0]", "time_s"), "ball.kicks[0].time_s");
}

TEST(Json, ErrorsNameTheFileAndTheKey) {
  const std::string f = "rig file 'r.json': cameras[1]";
  json o = {{"x", "wide"}, {"n", 2.5}, {"v", {1, 2}}, {"big", 1LL << 40}};
  ExpectNames(ErrorOf([&] { JsonNumber(o, "y", f); }), {"r.json", "cameras[1]", "missing", "'y'"});
  ExpectNames(ErrorOf([&] { JsonNumber(o, "x", f); }), {"r.json", "'x'", "number"});
  ExpectNames(ErrorOf([&] { JsonInt(o, "n", f); }), {"r.json", "'n'", "integer"});
  ExpectNames(ErrorOf([&] { JsonInt(o, "big", f); }), {"r.json", "'big'", "range"});
  ExpectNames(ErrorOf([&] { JsonInt64(o, "n", f); }), {"r.json", "'n'", "integer"});
  ExpectNames(ErrorOf([&] {
                JsonInt64(json{{"u", UINT64_MAX}}, "u", f);
              }),
              {"r.json", "'u'", "range"});
  ExpectNames(ErrorOf([&] { JsonBool(o, "x", f); }), {"r.json", "'x'", "true or false"});
  ExpectNames(ErrorOf([&] { JsonString(o, "n", f); }), {"r.json", "'n'", "string"});
  ExpectNames(ErrorOf([&] { JsonVector<3>(o, "v", f); }), {"r.json", "'v'", "3 numbers"});
  ExpectNames(ErrorOf([&] { JsonArray(o, "x", f); }), {"r.json", "'x'", "array"});
  ExpectNames(ErrorOf([&] { JsonObject(o, "x", f); }), {"r.json", "'x'", "object"});
  ExpectNames(ErrorOf([&] {
                JsonKnownKeys(o, f, {"x", "n", "v"});
              }),
              {"r.json", "unknown key 'big'", "known: x, n, v"});
  ExpectNames(ErrorOf([&] { JsonNumber(o, "y", ""); }), {"missing key 'y'"});
  // NaN cannot come from a parsed file, but from a value built in code.
  o["v"] = {1.0, NAN, 3.0};
  ExpectNames(ErrorOf([&] { JsonVector<3>(o, "v", f); }), {"'v'", "element 1", "not finite"});
  ExpectNames(ErrorOf([&] { JsonNumbers(o, "v", f); }), {"'v'", "element 1", "not finite"});
  o["x"] = {1, "a"};
  ExpectNames(ErrorOf([&] { JsonNumbers(o, "x", f); }), {"'x'", "element 1", "not a number"});
  ExpectNames(ErrorOf([&] { JsonVectorOf<2>(json(3), "placements[4]"); }),
              {"placements[4]", "2 numbers"});
}

TEST(Json, NestingDepthIgnoresStringsAndDeepFilesAreRefused) {
  EXPECT_EQ(JsonNestingDepth(R"({"a": [1, {"b": [[]]}]})"), 5);
  EXPECT_EQ(JsonNestingDepth(R"({"a": "[[[{{{\"]]]"})"), 1);  // brackets in a string
  EXPECT_EQ(JsonNestingDepth("3"), 0);
  // Counting stops once past the limit it is given.
  EXPECT_EQ(JsonNestingDepth(std::string(1000, '['), 10), 11);
  const std::string path = ::testing::TempDir() + "fv_deep.json";
  {
    std::ofstream out(path);
    out << std::string(100000, '[') << std::string(100000, ']');
  }
  ExpectNames(ErrorOf([&] { ReadJsonFile(path, "rig"); }), {"rig file", "fv_deep.json", "deeper"});
  {
    std::ofstream out(path);
    out << "{\"a\": [[1]]}";
  }
  EXPECT_EQ(ReadJsonFile(path, "rig")["a"][0][0], 1);
  std::remove(path.c_str());
}

TEST(Json, VectorWriterRoundTrips) {
  const Eigen::Vector3d v(0.25, -1.0, 3e8);
  const json j = JsonFromVector(v);
  EXPECT_EQ(j.dump(), "[0.25,-1.0,300000000.0]");
  EXPECT_EQ(JsonVectorOf<3>(json::parse(j.dump()), "v"), v);
  EXPECT_EQ(JsonFromVector(Eigen::Vector2d(1, 2)).size(), 2u);
  EXPECT_EQ(JsonFromVector(Eigen::Vector3d(0.123456, -2.5e-5, 7), 4).dump(), "[0.1235,-0.0,7.0]");
  EXPECT_DOUBLE_EQ(JsonRound(1.23456, 2), 1.23);
  EXPECT_DOUBLE_EQ(JsonRound(-1.235, 0), -1.0);
}

}  // namespace
}  // namespace fv::util
