#include "fieldvision/field/field.h"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/field/field_draw.h"
#include "fieldvision/field/field_json.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::field {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

Eigen::Vector3d Kp(const FieldModel& f, const std::string& name) {
  const FieldKeypoint* k = f.FindKeypoint(name);
  EXPECT_NE(k, nullptr) << f.name << " lacks keypoint " << name;
  return k ? k->position_m : Eigen::Vector3d::Constant(NAN);
}

// Distance between two keypoints measured to the outer edges of their lines.
double OuterSpan(const FieldModel& f, const std::string& a, const std::string& b) {
  return (Kp(f, a) - Kp(f, b)).norm() + f.line_width_m;
}

TEST(Fields, AllBuiltinsAreValidAndRoundTripThroughJson) {
  for (const auto& name : BuiltinFieldNames()) {
    SCOPED_TRACE(name);
    const FieldModel f = BuiltinField(name);
    EXPECT_NO_THROW(f.Check());
    EXPECT_GT(f.keypoints.size(), 10u);
    EXPECT_GT(f.segments.size(), 4u);
    const std::string path = testing::TempDir() + "/" + name + ".json";
    WriteFieldJson(f, path);
    const FieldModel g = LoadField(path);
    EXPECT_EQ(g.keypoints.size(), f.keypoints.size());
    EXPECT_EQ(g.arcs.size(), f.arcs.size());
    EXPECT_DOUBLE_EQ(g.length_m, f.length_m);
    // Every keypoint on the ground lies on or next to a painted line, except marks and
    // reference points drawn nowhere.
    for (const auto& k : f.keypoints) {
      if (k.position_m.z() != 0 || k.name.find("basket") != std::string::npos ||
          k.name.find("net") != std::string::npos || k.name == "centre") {
        continue;
      }
      EXPECT_LT(f.DistanceToPaint(k.position_m.head<2>()), 1e-9) << k.name;
    }
  }
}

TEST(Fields, FifaRuleBookDimensions) {
  const FieldModel f = BuiltinField("fifa");
  EXPECT_NEAR(OuterSpan(f, "corner_left_top", "corner_right_top"), 105.0, 1e-9);
  EXPECT_NEAR(OuterSpan(f, "corner_left_top", "corner_left_bottom"), 68.0, 1e-9);
  EXPECT_NEAR(OuterSpan(f, "penalty_area_left_top", "penalty_area_left_bottom"), 40.32, 1e-9);
  EXPECT_NEAR(OuterSpan(f, "goal_area_right_top", "goal_area_right_bottom"), 18.32, 1e-9);
  // 16.5 m from the goal line's outer edge to the penalty area line's outer edge.
  EXPECT_NEAR(52.5 - std::abs(Kp(f, "penalty_area_left_top").x()) + 0.06, 16.5, 1e-9);
  EXPECT_NEAR(52.5 - std::abs(Kp(f, "penalty_mark_right").x()), 11.0, 1e-9);
  EXPECT_NEAR(Kp(f, "centre_circle_top").y() + 0.06, 9.15, 1e-9);
  // Goal: 7.32 m between the posts' inner faces, bar 2.44 m high.
  const double post_centres = Kp(f, "goal_left_post_top").y() - Kp(f, "goal_left_post_bottom").y();
  EXPECT_NEAR(post_centres - 0.12, 7.32, 1e-9);
  EXPECT_NEAR(Kp(f, "goal_left_post_top_high").z(), 2.44, 1e-12);
}

TEST(Fields, MslRuleBookDimensions) {
  const FieldModel f = BuiltinField("robocup-msl");
  EXPECT_NEAR(OuterSpan(f, "corner_left_top", "corner_right_top"), 18.0, 1e-9);
  EXPECT_NEAR(OuterSpan(f, "corner_right_top", "corner_right_bottom"), 12.0, 1e-9);
  EXPECT_NEAR(OuterSpan(f, "penalty_area_left_top", "penalty_area_left_bottom"), 6.5, 1e-9);
  EXPECT_NEAR(OuterSpan(f, "goal_area_left_top", "goal_area_left_bottom"), 3.5, 1e-9);
  EXPECT_NEAR(9.0 - std::abs(Kp(f, "penalty_mark_left").x()), 3.0, 1e-9);
  EXPECT_DOUBLE_EQ(f.line_width_m, 0.125);
  EXPECT_NEAR(Kp(f, "centre_circle_right").x() + f.line_width_m / 2, 2.0, 1e-9);
}

TEST(Fields, FutsalRuleBookDimensions) {
  const FieldModel f = BuiltinField("futsal");
  EXPECT_NEAR(OuterSpan(f, "corner_left_top", "corner_right_top"), 40.0, 1e-9);
  EXPECT_NEAR(OuterSpan(f, "corner_left_top", "corner_left_bottom"), 20.0, 1e-9);
  // The straight part of the penalty area joins the quarter circles: 3.16 m between outer posts.
  EXPECT_NEAR((Kp(f, "penalty_area_left_top") - Kp(f, "penalty_area_left_bottom")).norm(), 3.16,
              1e-9);
  EXPECT_NEAR(20.0 - std::abs(Kp(f, "penalty_mark_left").x()), 6.0, 1e-9);
  EXPECT_NEAR(20.0 - std::abs(Kp(f, "second_penalty_mark_right").x()), 10.0, 1e-9);
}

TEST(Fields, BasketballRuleBookDimensions) {
  const FieldModel f = BuiltinField("basketball-fiba");
  // 28 x 15 m to the inner edges of the boundary lines.
  EXPECT_NEAR((Kp(f, "corner_left_top") - Kp(f, "corner_right_top")).norm() - 0.05, 28.0, 1e-9);
  EXPECT_NEAR((Kp(f, "corner_left_top") - Kp(f, "corner_left_bottom")).norm() - 0.05, 15.0, 1e-9);
  const Eigen::Vector3d hoop = Kp(f, "hoop_left");
  EXPECT_NEAR(hoop.z(), 3.05, 1e-12);
  EXPECT_NEAR(14.0 - std::abs(hoop.x()), 1.575, 1e-9);
  // Three-point arc: 6.75 m from the point below the basket to the arc's outer edge.
  EXPECT_NEAR(std::abs(Kp(f, "three_point_left_centre").x() - hoop.x()) + 0.025, 6.75, 1e-9);
  // Its straight parts 0.90 m from the side lines' inner edges.
  EXPECT_NEAR(7.5 - std::abs(Kp(f, "three_point_left_top").y()) - 0.025, 0.90, 1e-9);
  EXPECT_NEAR(OuterSpan(f, "restricted_area_left_top", "restricted_area_left_bottom"), 4.90, 1e-9);
  EXPECT_NEAR(14.0 - std::abs(Kp(f, "restricted_area_left_top").x()) + 0.025, 5.80, 1e-9);
  ASSERT_EQ(f.hoops.size(), 2u);
}

TEST(Fields, TennisRuleBookDimensions) {
  const FieldModel f = BuiltinField("tennis");
  EXPECT_NEAR((Kp(f, "corner_left_top") - Kp(f, "corner_right_top")).norm() + 0.10, 23.77, 1e-9);
  EXPECT_NEAR(OuterSpan(f, "corner_left_top", "corner_left_bottom"), 10.97, 1e-9);
  EXPECT_NEAR(OuterSpan(f, "singles_corner_left_top", "singles_corner_left_bottom"), 8.23, 1e-9);
  EXPECT_NEAR(std::abs(Kp(f, "service_left_centre").x()) + 0.025, 6.40, 1e-9);
  EXPECT_NEAR(Kp(f, "net_centre").z(), 0.914, 1e-12);
}

TEST(Fields, DistancesToLines) {
  const FieldModel f = BuiltinField("robocup-msl");
  EXPECT_NEAR(f.DistanceToLineCentres({0, 0.5}), 0.0, 1e-12);      // on the halfway line
  EXPECT_NEAR(f.DistanceToLineCentres({1.0, 0.0}), 0.9375, 1e-9);  // between line and circle
  EXPECT_LT(f.DistanceToPaint({0.05, 3.0}), 0.0);
  const auto samples = f.SampleLines(0.1);
  for (const auto& p : samples) EXPECT_LT(f.DistanceToLineCentres(p), 1e-9);
}

TEST(Fields, BadNamesAndFiles) {
  EXPECT_THAT([&] { BuiltinField("rugby"); }, ThrowsMessage<Error>(HasSubstr("robocup-msl")));
  const std::string dir = testing::TempDir();
  std::ofstream(dir + "/bad.json") << "{ not json";
  EXPECT_THROW(LoadField(dir + "/bad.json"), Error);
  std::ofstream(dir + "/nolen.json") << R"({"name": "x", "width_m": 10})";
  EXPECT_THAT([&] { LoadField(dir + "/nolen.json"); }, ThrowsMessage<Error>(HasSubstr("length_m")));
  std::ofstream(dir + "/dup.json")
      << R"({"length_m": 10, "width_m": 5, "keypoints": [{"name": "a", "position_m": [0,0,0]},
            {"name": "a", "position_m": [1,0,0]}]})";
  EXPECT_THROW(LoadField(dir + "/dup.json"), Error);
  EXPECT_THROW(LoadField(dir + "/missing.json"), Error);
  // Sizes no sports ground has (maps and grids are sized from them) are refused, named.
  for (const std::string size :
       {R"("length_m": 1e308, "width_m": 1e308)", R"("length_m": 1001, "width_m": 500)",
        R"("length_m": 1, "width_m": 1000)",
        R"("length_m": 100, "width_m": 50, "surround_m": 1e9)"}) {
    SCOPED_TRACE(size);
    std::ofstream(dir + "/huge.json", std::ios::trunc) << "{\"name\": \"huge\", " << size << "}";
    EXPECT_THAT([&] { LoadField(dir + "/huge.json"); }, ThrowsMessage<Error>(HasSubstr("huge")));
  }
  // So is anything painted or named beyond that reach (a keypoint at 1e308 was printed whole).
  for (const auto& [part, what] : std::vector<std::pair<std::string, std::string>>{
           {R"("keypoints": [{"name": "far", "position_m": [1e308, 0, 0]}])", "keypoint 'far'"},
           {R"("arcs": [{"name": "wide", "centre": [0, 0], "radius_m": 1e9}])", "arc 'wide'"},
           {R"("segments": [{"name": "long", "a": [0, 0], "b": [5e3, 0]}])", "line 'long'"}}) {
    std::ofstream(dir + "/far.json", std::ios::trunc)
        << R"({"name": "far", "length_m": 100, "width_m": 50, )" << part << "}";
    EXPECT_THAT([&] { LoadField(dir + "/far.json"); }, ThrowsMessage<Error>(HasSubstr(what + " ")))
        << part;
  }
  std::ofstream(dir + "/polo.json", std::ios::trunc) << R"({"length_m": 275, "width_m": 146})";
  EXPECT_NO_THROW(LoadField(dir + "/polo.json"));
}

TEST(FieldDraw, TopViewMapsCornersAndDrawsLines) {
  const FieldModel f = BuiltinField("robocup-msl");
  const TopView v = TopView::ForField(f, 840);
  EXPECT_EQ(v.size.width, 840);
  const cv::Point2d c = v.ToPixel({0, 0});
  EXPECT_NEAR(c.x, 420, 1e-9);
  EXPECT_NEAR(c.y, v.size.height / 2.0, 1e-9);
  const Eigen::Vector2d back = v.ToField(v.ToPixel({3.0, -2.0}));
  EXPECT_NEAR(back.x(), 3.0, 1e-12);
  EXPECT_NEAR(back.y(), -2.0, 1e-12);
  const cv::Mat img = DrawField(f, v);
  // The halfway line is white at the centre column, grass beside it.
  const cv::Vec3b& on = img.at<cv::Vec3b>(static_cast<int>(c.y) + 40, static_cast<int>(c.x));
  const cv::Vec3b& off = img.at<cv::Vec3b>(static_cast<int>(c.y) + 40, static_cast<int>(c.x) + 20);
  EXPECT_GT(on[0], 200);
  EXPECT_LT(off[0], 100);
}

}  // namespace
}  // namespace fv::field
