#include "fieldvision/plan/plan_run.h"

#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::plan {
namespace {

using nlohmann::json;

std::string WriteCornerRig(const std::string& dir) {
  json cams = json::array();
  for (const auto& [x, y] : {std::pair{-10.0, -7.0}, {10.0, -7.0}, {10.0, 7.0}, {-10.0, 7.0}}) {
    cams.push_back({{"position", {x, y, 4.0}}, {"look_at", {0, 0, 0}}});
  }
  const json rig = {{"name", "corners"},
                    {"defaults", {{"image_width", 1280}, {"image_height", 960}, {"hfov_deg", 80}}},
                    {"cameras", cams}};
  std::string path = dir + "/rig.json";
  std::ofstream(path) << rig.dump(2);
  return path;
}

// A run over the corner rig in `dir` into dir/out.
PlanRunOptions CornerRigRun(const std::string& dir, double grid_step_m, int map_width_px) {
  PlanRunOptions o;
  o.rig_path = WriteCornerRig(dir);
  o.out_dir = dir + "/out";
  o.coverage.grid_step_m = grid_step_m;
  o.map.width_px = map_width_px;
  return o;
}

TEST(PlanRunTest, WritesCoverageJsonAndMaps) {
  const std::string dir = fv::testing::TempDir();
  PlanRunOptions o = CornerRigRun(dir, 0.5, 400);
  const PlanRunResult r = RunPlan(o);
  ASSERT_EQ(r.coverage.layers.size(), 2u);
  std::ifstream in(o.out_dir + "/coverage.json");
  const json j = json::parse(in);
  ASSERT_EQ(j["fraction_exactly"].size(), 5u);
  double sum = 0;
  for (size_t k = 0; k < 5; ++k) {
    EXPECT_DOUBLE_EQ(j["fraction_exactly"][k].get<double>(),
                     r.coverage.layers[0].fraction_exactly[k]);
    sum += j["fraction_exactly"][k].get<double>();
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_EQ(j["layers"].size(), 2u);
  EXPECT_TRUE(j["error"]["max_m"].is_number());
  for (const char* name :
       {"coverage", "angle", "error", "coverage_above", "angle_above", "error_above"}) {
    const cv::Mat img = cv::imread(o.out_dir + "/" + name + ".png");
    EXPECT_EQ(img.cols, 400) << name;
  }
  EXPECT_NE(r.summary.find("share of the field"), std::string::npos);
  EXPECT_EQ(r.summary.find("warning"), std::string::npos) << r.summary;
  // The same camera twice counts as two cameras at a 0 degree angle: said.
  json twice = json::parse(std::ifstream(o.rig_path));
  twice["cameras"][1] = twice["cameras"][0];
  std::ofstream(o.rig_path) << twice.dump(2);
  o.out_dir = dir + "/twice";
  const PlanRunResult t = RunPlan(o);
  EXPECT_NE(t.summary.find("stand at one place looking one way"), std::string::npos) << t.summary;
}

TEST(PlanRunTest, OptimizeWritesARigThatReadsBack) {
  const std::string dir = fv::testing::TempDir();
  PlanRunOptions o;
  o.optimize = true;
  o.rig_path = WriteCornerRig(dir);  // scored for comparison
  o.out_dir = dir + "/out";
  o.coverage.grid_step_m = 1.0;
  o.coverage.height_above_m = 0;
  o.search.grid_step_m = 1.5;
  o.search.iterations = 60;
  o.search.restarts = 1;
  o.map.width_px = 300;
  const PlanRunResult r = RunPlan(o);
  ASSERT_TRUE(r.optimized && r.given_rig_score && r.given_rig_search_score);
  const Rig back = ReadRigJson(o.out_dir + "/rig.json");
  ASSERT_EQ(back.cameras.size(), 4u);
  CoverageOptions c = o.coverage;
  EXPECT_NEAR(EvaluateCoverage(back.cameras, field::LoadField("robocup-msl"), c).score(),
              r.coverage.score(), 1e-9);
  EXPECT_EQ(back.field, "robocup-msl");  // the field it was searched on, by name
}

// A rig file's field is the run's unless --field names another (said); one that is not a field
// is an error naming it (it was ignored: robocup-msl, silently).
TEST(PlanRunTest, TheRigFilesFieldIsUsed) {
  const std::string dir = fv::testing::TempDir();
  PlanRunOptions o = CornerRigRun(dir, 2.0, 200);
  o.coverage.height_above_m = 0;
  json rig = json::parse(std::ifstream(o.rig_path));
  rig["field"] = "fifa";
  std::ofstream(o.rig_path) << rig.dump(2);
  EXPECT_NE(RunPlan(o).summary.find("field fifa (105.00 x 68.00 m)"), std::string::npos);
  o.field = "robocup-msl";
  const std::string replaced = RunPlan(o).summary;
  EXPECT_NE(replaced.find("note: --field robocup-msl used; the rig file names field fifa"),
            std::string::npos)
      << replaced;
  EXPECT_NE(replaced.find("field robocup-msl (18.00 x 12.00 m)"), std::string::npos) << replaced;
  o.field.clear();
  rig["field"] = "no-such-field";
  std::ofstream(o.rig_path) << rig.dump(2);
  std::string error;
  try {
    RunPlan(o);
  } catch (const Error& e) {
    error = e.what();
  }
  EXPECT_NE(error.find("no-such-field"), std::string::npos) << error;
  // A rig searched on a field file names it by its path from the rig's folder: read back, the
  // rig is on that field (it fell back to robocup-msl).
  std::ofstream(dir + "/pitch40.json") << R"({"name": "pitch40", "length_m": 40, "width_m": 20})";
  PlanRunOptions search = o;
  search.rig_path.clear();
  search.optimize = true;
  search.field = dir + "/pitch40.json";
  search.out_dir = dir + "/searched";
  search.search.grid_step_m = 4.0;
  search.search.iterations = 20;
  search.search.restarts = 1;
  search.search.num_cameras = 2;
  RunPlan(search);
  PlanRunOptions again = o;
  again.rig_path = search.out_dir + "/rig.json";
  again.out_dir = dir + "/again";
  EXPECT_NE(RunPlan(again).summary.find("field pitch40 (40.00 x 20.00 m)"), std::string::npos);
}

TEST(PlanRunTest, BadInputGivesOneLineErrors) {
  const std::string dir = fv::testing::TempDir();
  auto error_of = [](const PlanRunOptions& o) -> std::string {
    try {
      RunPlan(o);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  PlanRunOptions o;
  o.out_dir = dir + "/out";
  o.rig_path = dir + "/nope.json";
  std::string msg = error_of(o);
  EXPECT_NE(msg.find("nope.json"), std::string::npos) << msg;
  o.rig_path = WriteCornerRig(dir);
  o.field = "rugby";
  msg = error_of(o);
  EXPECT_NE(msg.find("rugby"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  o.field = "robocup-msl";
  o.rig_path.clear();
  msg = error_of(o);
  EXPECT_NE(msg.find("--rig"), std::string::npos) << msg;
  o.rig_path = WriteCornerRig(dir);
  o.coverage.pixel_noise_px = -1;
  msg = error_of(o);
  EXPECT_NE(msg.find("pixel_noise_px"), std::string::npos) << msg;
  o.coverage.pixel_noise_px = 1;
  // The rig given is in the output folder under the name the optimised rig gets: refused before
  // anything is written, the user's rig kept.
  {
    PlanRunOptions in_place = o;
    in_place.optimize = true;
    in_place.out_dir = dir;  // WriteCornerRig wrote dir/rig.json
    std::ifstream before_in(in_place.rig_path);
    const std::string before((std::istreambuf_iterator<char>(before_in)), {});
    msg = error_of(in_place);
    EXPECT_NE(msg.find("--out"), std::string::npos) << msg;
    EXPECT_NE(msg.find("rig.json"), std::string::npos) << msg;
    std::ifstream after_in(in_place.rig_path);
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(after_in)), {}), before);
    // Without --optimize nothing is written over it: the maps go beside the rig.
    in_place.optimize = false;
    in_place.coverage.grid_step_m = 2.0;
    in_place.map.width_px = 200;
    EXPECT_NO_THROW(RunPlan(in_place));
    EXPECT_TRUE(std::filesystem::exists(dir + "/coverage.json"));
  }
  // A camera 1e300 m away (it saw nothing and the rig was planned without a word).
  {
    json rig = json::parse(std::ifstream(WriteCornerRig(dir)));
    rig["cameras"][0]["position"] = {1e300, -7.0, 4.0};
    std::ofstream(dir + "/far.json") << rig.dump();
  }
  o.rig_path = dir + "/far.json";
  msg = error_of(o);
  EXPECT_NE(msg.find("far.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("10 km"), std::string::npos) << msg;
  o.rig_path = WriteCornerRig(dir);
  o.map.width_px = 20000;  // six such maps took 2.6 GB
  msg = error_of(o);
  EXPECT_NE(msg.find("width_px"), std::string::npos) << msg;
}

}  // namespace
}  // namespace fv::plan
