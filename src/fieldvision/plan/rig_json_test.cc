#include "fieldvision/plan/rig_json.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::plan {
namespace {

using nlohmann::json;

// The message of the fv::Error thrown by f; fails the test if none (or another type) is thrown.
template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected fv::Error";
  return "";
}

void ExpectOneLineNaming(const std::string& msg, const std::vector<std::string>& words) {
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  for (const auto& w : words) EXPECT_NE(msg.find(w), std::string::npos) << msg << " lacks " << w;
}

json CornerCamera(double x, double y) {
  return {{"name", "c"}, {"position", {x, y, 4.0}}, {"look_at", {0, 0, 0}}};
}

TEST(RigTest, ReadsLookAtYawPitchAndDefaults) {
  fv::testing::SeededRng rng(3);
  const Eigen::Vector3d eye(rng.Uniform(-12, 12), rng.Uniform(-8, 8), rng.Uniform(2, 8));
  const Eigen::Vector3d target(rng.Uniform(-5, 5), rng.Uniform(-3, 3), 0);
  const Eigen::Vector3d d = target - eye;
  const double yaw = std::atan2(d.y(), d.x()) * 180 / M_PI;
  const double pitch = std::atan2(-d.z(), d.head<2>().norm()) * 180 / M_PI;
  const json j = {{"name", "test"},
                  {"defaults", {{"image_width", 1280}, {"image_height", 960}, {"hfov_deg", 80}}},
                  {"cameras",
                   {{{"name", "a"},
                     {"position", {eye.x(), eye.y(), eye.z()}},
                     {"look_at", {target.x(), target.y(), target.z()}}},
                    {{"name", "b"},
                     {"position", {eye.x(), eye.y(), eye.z()}},
                     {"yaw_deg", yaw},
                     {"pitch_deg", pitch},
                     {"focal_px", 1000.0}}}}};
  const Rig rig = RigFromJson(j, "rig", "");
  ASSERT_EQ(rig.cameras.size(), 2u);
  const camera::Camera& a = rig.cameras[0];
  const camera::Camera& b = rig.cameras[1];
  EXPECT_EQ(a.width, 1280);
  EXPECT_NEAR(a.fx, 640 / std::tan(40 * M_PI / 180), 1e-9);
  EXPECT_NEAR(b.fx, 1000.0, 1e-12);
  EXPECT_NEAR((a.CentreInWorld() - eye).norm(), 0, 1e-9);
  EXPECT_LT(geometry::RotationAngleBetween(a.cam_from_world.rotation, b.cam_from_world.rotation),
            1e-9);
  // The aim point projects to the principal point.
  const auto uv = a.Project(target);
  ASSERT_TRUE(uv.has_value());
  EXPECT_NEAR(uv->x(), a.cx, 1e-6);
  EXPECT_NEAR(uv->y(), a.cy, 1e-6);
}

TEST(RigTest, WriteReadRoundTripIncludingYamlCameras) {
  fv::testing::SeededRng rng(4);
  const std::string dir = fv::testing::TempDir();
  Rig rig;
  rig.name = "round trip";
  rig.cameras.push_back(MakeAimedCamera("aimed", 1920, 1080, rng.Uniform(50, 100), {-10, -7, 4},
                                        {rng.Uniform(-3, 3), 0, 0}));
  rig.cameras.push_back(
      MakeAimedCamera("rolled", 800, 600, 70, {10, 7, 5}, {0, 0, 0}, rng.Uniform(-20, 20)));
  rig.cameras[1].distortion = {-0.1, 0.01, 0, 0, 0};
  rig.cameras[1].cx += 3.5;
  WriteRigJson(rig, dir + "/rig.json");
  const Rig back = ReadRigJson(dir + "/rig.json");
  ASSERT_EQ(back.cameras.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    const camera::Camera& x = rig.cameras[k];
    const camera::Camera& y = back.cameras[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.width, y.width);
    EXPECT_NEAR(x.fx, y.fx, 1e-9);
    EXPECT_NEAR(x.cx, y.cx, 1e-9);
    EXPECT_EQ(x.distortion, y.distortion);
    EXPECT_NEAR((x.CentreInWorld() - y.CentreInWorld()).norm(), 0, 1e-9);
    EXPECT_LT(geometry::RotationAngleBetween(x.cam_from_world.rotation, y.cam_from_world.rotation),
              1e-9);
  }
  // A rig listing camera YAMLs, relative to the rig file.
  camera::WriteCameraYaml(rig.cameras[1], dir + "/cam.yaml");
  std::ofstream(dir + "/yaml_rig.json") << json({{"cameras", {{{"yaml", "cam.yaml"}}}}}).dump();
  const Rig from_yaml = ReadRigJson(dir + "/yaml_rig.json");
  ASSERT_EQ(from_yaml.cameras.size(), 1u);
  EXPECT_NEAR((from_yaml.cameras[0].CentreInWorld() - rig.cameras[1].CentreInWorld()).norm(), 0,
              1e-9);
}

TEST(RigTest, BadInputGivesOneLineErrors) {
  const std::string dir = fv::testing::TempDir();
  ExpectOneLineNaming(ErrorOf([&] { ReadRigJson(dir + "/missing.json"); }),
                      {"missing.json", "does not exist"});
  std::ofstream(dir + "/broken.json") << "{\"cameras\": [ {\"position\": [1, 2,, 3]} ]}";
  ExpectOneLineNaming(ErrorOf([&] { ReadRigJson(dir + "/broken.json"); }),
                      {"broken.json", "not valid JSON"});
  std::ofstream(dir + "/huge.json")
      << "{\"cameras\": [{\"position\": [1, 1e999, 3], \"look_at\": [0, 0, 0]}]}";
  ExpectOneLineNaming(ErrorOf([&] { ReadRigJson(dir + "/huge.json"); }),
                      {"huge.json", "not valid JSON", "1e999"});
  const json defaults = {{"image_width", 640}, {"image_height", 480}, {"hfov_deg", 60}};
  // Zero cameras.
  ExpectOneLineNaming(ErrorOf([&] {
                        RigFromJson({{"cameras", json::array()}}, "r.json", "");
                      }),
                      {"r.json", "no cameras"});
  // A mounts file (plan --optimize --mounts) given as a rig says where it goes.
  ExpectOneLineNaming(ErrorOf([&] {
                        RigFromJson({{"mounts", json::array()}}, "m.json", "");
                      }),
                      {"m.json", "--optimize --mounts"});
  // Missing key, named with the camera's index.
  ExpectOneLineNaming(ErrorOf([&] {
                        RigFromJson(
                            {{"defaults", defaults},
                             {"cameras", {CornerCamera(-10, -7), {{"look_at", {0, 0, 0}}}}}},
                            "r.json", "");
                      }),
                      {"r.json", "cameras[1]", "'position'"});
  // Misspelt key.
  ExpectOneLineNaming(ErrorOf([&] {
                        RigFromJson(
                            {{"defaults", defaults},
                             {"cameras", {{{"postion", {1, 2, 3}}, {"look_at", {0, 0, 0}}}}}},
                            "r.json", "");
                      }),
                      {"cameras[0]", "'postion'"});
  // Under the ground (z down by mistake): planned as seeing 90 % of the field from below.
  ExpectOneLineNaming(ErrorOf([&] {
                        RigFromJson(
                            {{"defaults", defaults},
                             {"cameras", {{{"position", {-10, -7, -4}}, {"look_at", {0, 0, 0}}}}}},
                            "r.json", "");
                      }),
                      {"r.json", "4 m below the ground"});
  // NaN in a position (a JSON value built in code: the parser itself rejects NaN).
  json nan_cam = CornerCamera(1, 2);
  nan_cam["position"][1] = NAN;
  ExpectOneLineNaming(ErrorOf([&] {
                        RigFromJson({{"defaults", defaults}, {"cameras", {nan_cam}}}, "r.json", "");
                      }),
                      {"cameras[0]", "'position'", "not finite"});
  // Wrong type.
  json str_cam = CornerCamera(1, 2);
  str_cam["image_width"] = "wide";
  ExpectOneLineNaming(ErrorOf([&] {
                        RigFromJson({{"defaults", defaults}, {"cameras", {str_cam}}}, "r.json", "");
                      }),
                      {"cameras[0]", "'image_width'"});
  // Two orientations.
  json two = CornerCamera(1, 2);
  two["yaw_deg"] = 10;
  two["pitch_deg"] = 10;
  ExpectOneLineNaming(ErrorOf([&] {
                        RigFromJson({{"defaults", defaults}, {"cameras", {two}}}, "r.json", "");
                      }),
                      {"cameras[0]", "orientation"});
  // A camera struct with NaN, and a camera file without a pose.
  Rig rig;
  rig.cameras.push_back(MakeAimedCamera("nan", 640, 480, 60, {1, 2, 3}, {0, 0, 0}));
  rig.cameras[0].cam_from_world.translation.x() = NAN;
  ExpectOneLineNaming(ErrorOf([&] { rig.Check("my rig"); }), {"my rig", "nan"});
  camera::Camera intrinsics_only = camera::Camera::FromFov(640, 480, 60);
  camera::WriteCameraYaml(intrinsics_only, dir + "/intr.yaml");
  ExpectOneLineNaming(ErrorOf([&] { RigFromCameraFiles({dir + "/intr.yaml"}); }),
                      {"intr.yaml", "no pose"});
}

}  // namespace
}  // namespace fv::plan
