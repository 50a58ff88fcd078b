// Camera rigs for planning: a list of posed cameras read from a rig JSON file (cameras given by
// position, aim point or yaw/pitch/roll or an OpenCV rvec, image size, focal length or field of
// view, optional distortion) or from camera YAML files (camera_io.h); written back as JSON.
//
// Rig JSON: {"name": ..., "defaults": {camera keys}, "cameras": [{camera keys} | {"yaml": path}]}
// Camera keys: "name", "position" [x, y, z] (m, world), one orientation: "look_at" [x, y, z] or
// "yaw_deg" (heading of the optical axis from +x towards +y) with "pitch_deg" (down tilt, > 0
// looks down) or "rvec" (OpenCV, cam_from_world); optional "roll_deg" (turn about the optical
// axis) with the first two; "image_width", "image_height"; one of "hfov_deg", "focal_px" (fx = fy)
// or "fx" + "fy"; optional "cx", "cy" (default: image centre) and "distortion" (OpenCV order).
// "defaults" supplies keys missing in every camera; a "yaml" path is relative to the rig file.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldvision/camera/camera.h"

namespace fv::plan {

struct Rig {
  std::string name;
  std::vector<camera::Camera> cameras;  // all with poses
  // The field the rig file names (a built-in name, or a field JSON resolved beside the file);
  // empty when it names none.
  std::string field;

  // Throws fv::Error naming `context` and the bad camera: no cameras, no pose, NaN, bad intrinsics.
  void Check(const std::string& context = "rig") const;
};

// A camera of the given size and horizontal field of view at `position_in_world` looking at
// `target_in_world` (image up towards +z), turned by `roll_deg` about its optical axis.
camera::Camera MakeAimedCamera(const std::string& name, int width, int height, double hfov_deg,
                               const Eigen::Vector3d& position_in_world,
                               const Eigen::Vector3d& target_in_world, double roll_deg = 0.0);

// `base_dir` resolves "yaml" paths; `context` (the file name) starts every error message.
Rig RigFromJson(const nlohmann::json& j, const std::string& context, const std::string& base_dir);
Rig ReadRigJson(const std::string& path);
// Cameras without roll are written as position + look_at (on the ground), others with an rvec.
nlohmann::json RigToJson(const Rig& rig);
void WriteRigJson(const Rig& rig, const std::string& path);
// A rig from camera YAML files (each must have a pose).
Rig RigFromCameraFiles(const std::vector<std::string>& paths);

}  // namespace fv::plan
