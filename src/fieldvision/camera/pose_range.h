// A camera's pose against the field it is meant for: a camera kilometres from the world origin
// is a pose in other units (millimetres read as metres) or of another world, never a camera
// that sees the field.
#pragma once

#include <string>

#include "fieldvision/camera/camera.h"

namespace fv::camera {

constexpr double kMaxCameraDistanceM = 1e4;

// Throws fv::Error "{what}: camera 'NAME' stands D m from the world origin (at most 10000 m):
// ..." for a posed camera farther away; a camera without a pose passes.
void CheckCameraNearOrigin(const Camera& camera, const std::string& what);

}  // namespace fv::camera
