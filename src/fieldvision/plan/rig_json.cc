#include "fieldvision/plan/rig_json.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/output_path.h"

namespace fv::plan {
namespace {

using nlohmann::json;

constexpr double kDeg = M_PI / 180.0;

const std::set<std::string> kOrientationKeys = {"look_at", "yaw_deg", "pitch_deg", "rvec"};
const std::set<std::string> kFocalKeys = {"hfov_deg", "focal_px", "fx", "fy"};
const std::set<std::string> kCameraKeys = {"name",         "position", "look_at",  "yaw_deg",
                                           "pitch_deg",    "roll_deg", "rvec",     "image_width",
                                           "image_height", "hfov_deg", "focal_px", "fx",
                                           "fy",           "cx",       "cy",       "distortion"};

int PositiveInt(const json& obj, const std::string& key, const std::string& ctx) {
  const int v = util::JsonInt(obj, key, ctx);
  FV_REQUIRE(v > 0 && v < 1000000, "{}: key '{}' must be a positive size (got {})", ctx, key, v);
  return v;
}

// Camera keys: `defaults` filled in where the camera lacks them; a camera's own orientation or
// focal keys replace the whole group from the defaults.
json Merge(const json& defaults, const json& cam) {
  json merged = cam;
  auto has_any = [&](const std::set<std::string>& keys) {
    for (const auto& k : keys) {
      if (cam.contains(k)) return true;
    }
    return false;
  };
  const bool own_orientation = has_any(kOrientationKeys);
  const bool own_focal = has_any(kFocalKeys);
  for (auto it = defaults.begin(); it != defaults.end(); ++it) {
    if (merged.contains(it.key())) continue;
    if (own_orientation && kOrientationKeys.count(it.key())) continue;
    if (own_focal && kFocalKeys.count(it.key())) continue;
    if (it.key() == "name") continue;
    merged[it.key()] = it.value();
  }
  return merged;
}

camera::Camera CameraFromJson(const json& j, const std::string& ctx) {
  FV_REQUIRE(j.is_object(), "{}: must be an object", ctx);
  for (auto it = j.begin(); it != j.end(); ++it) {
    FV_REQUIRE(kCameraKeys.count(it.key()), "{}: unknown key '{}'", ctx, it.key());
  }
  camera::Camera cam;
  const int width = PositiveInt(j, "image_width", ctx);
  const int height = PositiveInt(j, "image_height", ctx);
  int num_focal = 0;
  for (const auto& k : {"hfov_deg", "focal_px", "fx"}) num_focal += j.contains(k) ? 1 : 0;
  FV_REQUIRE(num_focal == 1, "{}: give exactly one of 'hfov_deg', 'focal_px' or 'fx' + 'fy'", ctx);
  if (j.contains("hfov_deg")) {
    const double hfov = util::JsonNumber(j, "hfov_deg", ctx);
    FV_REQUIRE(hfov > 0 && hfov < 180, "{}: key 'hfov_deg' must be in (0, 180) (got {})", ctx,
               hfov);
    cam = camera::Camera::FromFov(width, height, hfov);
  } else {
    cam = camera::Camera::FromFov(width, height, 90.0);
    if (j.contains("focal_px")) {
      cam.fx = cam.fy = util::JsonNumber(j, "focal_px", ctx);
    } else {
      cam.fx = util::JsonNumber(j, "fx", ctx);
      cam.fy = util::JsonNumber(j, "fy", ctx);
    }
    FV_REQUIRE(cam.fx > 0 && cam.fy > 0, "{}: focal length must be > 0", ctx);
  }
  if (j.contains("cx")) cam.cx = util::JsonNumber(j, "cx", ctx);
  if (j.contains("cy")) cam.cy = util::JsonNumber(j, "cy", ctx);
  if (j.contains("distortion")) cam.distortion = util::JsonNumbers(j, "distortion", ctx);
  cam.name = util::JsonString(j, "name", ctx, cam.name);
  const Eigen::Vector3d eye = util::JsonVector<3>(j, "position", ctx);
  // A position kilometres away is a typo (1e300 ended up at the origin of the pose arithmetic).
  FV_REQUIRE(eye.lpNorm<Eigen::Infinity>() <= 1e4,
             "{}: key 'position' must be within 10 km of the field centre (got {}, {}, {})", ctx,
             eye.x(), eye.y(), eye.z());
  const double roll_deg = j.contains("roll_deg") ? util::JsonNumber(j, "roll_deg", ctx) : 0.0;
  int num_orient = 0;
  for (const auto& k : {"look_at", "yaw_deg", "rvec"}) num_orient += j.contains(k) ? 1 : 0;
  FV_REQUIRE(num_orient == 1,
             "{}: give exactly one orientation: 'look_at', 'yaw_deg' + 'pitch_deg' or 'rvec'", ctx);
  Eigen::Vector3d target;
  if (j.contains("rvec")) {
    FV_REQUIRE(!j.contains("roll_deg"), "{}: 'roll_deg' cannot be combined with 'rvec'", ctx);
    const Eigen::Vector3d rvec = util::JsonVector<3>(j, "rvec", ctx);
    const Eigen::Matrix3d rot = geometry::RotationFromRvec(rvec);
    cam.cam_from_world = geometry::Rigid3d{rot, -rot * eye};
    cam.has_pose = true;
  } else {
    if (j.contains("look_at")) {
      target = util::JsonVector<3>(j, "look_at", ctx);
      FV_REQUIRE((target - eye).norm() > 1e-6, "{}: 'look_at' equals 'position'", ctx);
    } else {
      const double yaw = util::JsonNumber(j, "yaw_deg", ctx) * kDeg;
      const double pitch = util::JsonNumber(j, "pitch_deg", ctx) * kDeg;
      target = eye + Eigen::Vector3d(std::cos(pitch) * std::cos(yaw),
                                     std::cos(pitch) * std::sin(yaw), -std::sin(pitch));
    }
    const camera::Camera aimed =
        MakeAimedCamera(cam.name, width, height, 90, eye, target, roll_deg);
    cam.cam_from_world = aimed.cam_from_world;
    cam.has_pose = true;
  }
  cam.Check(ctx);
  return cam;
}

}  // namespace

void Rig::Check(const std::string& context) const {
  FV_REQUIRE(!cameras.empty(), "{}: the rig has no cameras", context);
  for (size_t i = 0; i < cameras.size(); ++i) {
    const camera::Camera& c = cameras[i];
    const std::string ctx = c.name.empty() ? fmt::format("{}: camera {}", context, i)
                                           : fmt::format("{}: camera {} '{}'", context, i, c.name);
    c.Check(ctx);
    FV_REQUIRE(c.has_pose, "{}: has no pose (rvec/tvec)", ctx);
    FV_REQUIRE(c.CentreInWorld().allFinite(), "{}: position is not finite", ctx);
    // The ground is opaque: nothing on the field is seen from under it (z down is the usual
    // cause).
    FV_REQUIRE(c.CentreInWorld().z() >= 0,
               "{}: {:.3g} m below the ground (z = {:.3g} m; z points up, the field at z = 0)", ctx,
               -c.CentreInWorld().z(), c.CentreInWorld().z());
  }
}

camera::Camera MakeAimedCamera(const std::string& name, int width, int height, double hfov_deg,
                               const Eigen::Vector3d& position_in_world,
                               const Eigen::Vector3d& target_in_world, double roll_deg) {
  camera::Camera cam = camera::Camera::FromFov(width, height, hfov_deg);
  cam.name = name;
  geometry::Rigid3d pose = geometry::Rigid3d::LookAt(position_in_world, target_in_world);
  if (roll_deg != 0.0) {
    const Eigen::Matrix3d roll =
        Eigen::AngleAxisd(roll_deg * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pose.rotation = roll.transpose() * pose.rotation;
    pose.translation = -pose.rotation * position_in_world;
  }
  cam.cam_from_world = pose;
  cam.has_pose = true;
  return cam;
}

Rig RigFromJson(const json& j, const std::string& context, const std::string& base_dir) {
  FV_REQUIRE(j.is_object(), "{}: the rig must be a JSON object with key 'cameras'", context);
  FV_REQUIRE(!j.contains("mounts"),
             "{}: a file of mounting places, not a rig: give it to plan --optimize --mounts",
             context);
  for (auto it = j.begin(); it != j.end(); ++it) {
    FV_REQUIRE(it.key() == "name" || it.key() == "cameras" || it.key() == "defaults" ||
                   it.key() == "field" || it.key() == "description" || it.key() == "score",
               "{}: unknown key '{}' (expected name, description, field, defaults, cameras)",
               context, it.key());
  }
  Rig rig;
  rig.name = util::JsonString(j, "name", context, rig.name);
  rig.field = util::JsonString(j, "field", context, "");
  if (!rig.field.empty() && !base_dir.empty()) {
    const std::filesystem::path beside = std::filesystem::path(base_dir) / rig.field;
    std::error_code ec;
    if (std::filesystem::is_regular_file(beside, ec)) rig.field = beside.string();
  }
  json defaults = json::object();
  if (j.contains("defaults")) {
    FV_REQUIRE(j["defaults"].is_object(), "{}: key 'defaults' must be an object", context);
    defaults = j["defaults"];
  }
  FV_REQUIRE(j.contains("cameras"), "{}: missing key 'cameras'", context);
  FV_REQUIRE(j["cameras"].is_array(), "{}: key 'cameras' must be an array", context);
  const json& cams = j["cameras"];
  for (size_t i = 0; i < cams.size(); ++i) {
    const std::string ctx = fmt::format("{}: cameras[{}]", context, i);
    FV_REQUIRE(cams[i].is_object(), "{}: must be an object", ctx);
    if (cams[i].contains("yaml")) {
      FV_REQUIRE(cams[i]["yaml"].is_string(), "{}: key 'yaml' must be a string", ctx);
      std::filesystem::path p(cams[i]["yaml"].get<std::string>());
      if (p.is_relative() && !base_dir.empty()) p = std::filesystem::path(base_dir) / p;
      camera::Camera cam = camera::ReadCameraYaml(p.string());
      FV_REQUIRE(cam.has_pose, "{}: camera file '{}' has no pose (rvec/tvec)", ctx, p.string());
      if (cams[i].contains("name") && cams[i]["name"].is_string()) {
        cam.name = cams[i]["name"].get<std::string>();
      }
      if (cam.name.empty()) cam.name = p.stem().string();
      rig.cameras.push_back(cam);
      continue;
    }
    camera::Camera cam = CameraFromJson(Merge(defaults, cams[i]), ctx);
    if (cam.name.empty()) cam.name = fmt::format("cam{}", i + 1);
    rig.cameras.push_back(cam);
  }
  rig.Check(context);
  return rig;
}

Rig ReadRigJson(const std::string& path) {
  const json j = util::ReadJsonFile(path, "rig");
  const std::string base = std::filesystem::path(path).parent_path().string();
  Rig rig = RigFromJson(j, "rig file '" + path + "'", base);
  if (rig.name.empty()) rig.name = std::filesystem::path(path).stem().string();
  return rig;
}

json RigToJson(const Rig& rig) {
  json j;
  j["name"] = rig.name;
  if (!rig.field.empty()) j["field"] = rig.field;
  j["cameras"] = json::array();
  for (const camera::Camera& c : rig.cameras) {
    json cj;
    cj["name"] = c.name;
    const Eigen::Vector3d eye = c.CentreInWorld();
    cj["position"] = util::JsonFromVector(eye);
    const Eigen::Vector3d axis = c.AxisInWorld();
    const geometry::Rigid3d look = geometry::Rigid3d::LookAt(eye, eye + axis);
    if (geometry::RotationAngleBetween(look.rotation, c.cam_from_world.rotation) < 1e-9) {
      Eigen::Vector3d target = eye + 10.0 * axis;
      if (axis.z() < -1e-6) target = eye + (-eye.z() / axis.z()) * axis;  // aim point on z = 0
      cj["look_at"] = util::JsonFromVector(target);
    } else {
      cj["rvec"] = util::JsonFromVector(c.cam_from_world.Rvec());
    }
    cj["image_width"] = c.width;
    cj["image_height"] = c.height;
    const bool centred =
        std::abs(c.cx - 0.5 * (c.width - 1)) < 1e-9 && std::abs(c.cy - 0.5 * (c.height - 1)) < 1e-9;
    if (c.fx == c.fy && centred) {
      cj["hfov_deg"] = 2.0 * std::atan(0.5 * c.width / c.fx) / kDeg;
    } else {
      cj["fx"] = c.fx;
      cj["fy"] = c.fy;
      cj["cx"] = c.cx;
      cj["cy"] = c.cy;
    }
    if (!c.distortion.empty()) cj["distortion"] = c.distortion;
    j["cameras"].push_back(cj);
  }
  return j;
}

void WriteRigJson(const Rig& rig, const std::string& path) {
  util::WriteTextFile(path, RigToJson(rig).dump(2) + "\n", "rig file");
}

Rig RigFromCameraFiles(const std::vector<std::string>& paths) {
  Rig rig;
  rig.name = "cameras";
  for (const auto& p : paths) {
    camera::Camera cam = camera::ReadCameraYaml(p);
    FV_REQUIRE(cam.has_pose, "camera file '{}' has no pose (rvec/tvec); plan needs posed cameras",
               p);
    if (cam.name.empty()) cam.name = std::filesystem::path(p).stem().string();
    rig.cameras.push_back(cam);
  }
  rig.Check("camera files");
  return rig;
}

}  // namespace fv::plan
