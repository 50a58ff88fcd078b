// Joint refinement of several calibrated cameras (a rig) from shared observations: field points
// of known position and points seen by several cameras whose position is unknown (triangulated,
// then free). Bundle adjustment with Ceres (Triggs et al., "Bundle adjustment - a modern
// synthesis", 1999) over every camera's pose and the free points, intrinsics fixed, Huber loss,
// through the camera's templated model (camera/projection.h). The known points fix the gauge.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"

namespace fv::calib {

struct RigObservation {
  std::string name;  // shared between cameras
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();
  std::optional<Eigen::Vector3d> p_world;  // known position (fixed), else a free point
};

// Reads a camera's observations: columns u,v,name and optionally x,y,z. A name that is a
// keypoint of `field` (may be null) gets its position; other names without x,y,z are free. With
// an image size, a point outside the image is an error naming the line (RequireInImage).
std::vector<RigObservation> ReadRigObservations(const std::string& path,
                                                const field::FieldModel* field, int width = 0,
                                                int height = 0);

struct RigOptions {
  double huber_px = 3.0;  // robust loss scale
  int max_iterations = 200;
  int min_known_points = 3;  // distinct known points over the rig (fix the gauge)
  int min_observations_per_camera = 4;
  void Check() const;
};

struct RigCameraReport {
  std::string name;
  int num_observations = 0;
  double rms_before_px = 0.0, rms_after_px = 0.0;
  double moved_mm = 0.0;  // camera centre change
  double rotated_deg = 0.0;
};

struct RigResult {
  std::vector<camera::Camera> cameras;  // refined, in input order
  std::vector<RigCameraReport> reports;
  std::vector<std::pair<std::string, Eigen::Vector3d>> free_points;  // refined positions
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  std::string Summary() const;
};

// Cameras must have poses; observations[i] belongs to cameras[i]. Throws fv::Error naming the
// camera or point when the input cannot define the rig (too few observations, a free point seen
// by one camera only, too few known points).
RigResult RefineRig(const std::vector<camera::Camera>& cameras,
                    const std::vector<std::vector<RigObservation>>& observations,
                    const RigOptions& options = {});

}  // namespace fv::calib
