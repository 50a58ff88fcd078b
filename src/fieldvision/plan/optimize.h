// Search for a camera rig: N cameras, each mounted somewhere on a set of allowed places (points
// or straight segments with heights) and aimed at a point on the ground inside the field, that
// maximises the coverage score (coverage.h: the share of the field seen by >= 2 cameras with a
// good pair angle, minus a weight times the worst expected error there, averaged over the ball's
// layers on the ground and in the air), evaluated on a coarse grid. Method: simulated annealing
// (Kirkpatrick et al., Science 220, 1983) with geometric cooling and shrinking moves, seeded
// restarts (the first from cameras spread evenly along the places and aimed at the centre), keeping
// the best rig seen.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"
#include "fieldvision/plan/coverage.h"
#include "fieldvision/plan/rig_json.h"

namespace fv::plan {

// A mounting place: the segment a -> b (a point when a == b), heights in the z coordinates.
struct MountPlace {
  std::string name;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double LengthM() const { return (b - a).norm(); }
  Eigen::Vector3d At(double t) const { return a + t * (b - a); }
};

// The rectangle `offset_m` outside the field's lines at `height_m`: its 4 sides, corners included.
std::vector<MountPlace> PerimeterMounts(const field::FieldModel& field, double offset_m,
                                        double height_m);
// {"mounts": [{"name": ..., "point": [x, y, z]} | {"name": ..., "line": [[x, y, z], [x, y, z]]}]}
std::vector<MountPlace> MountsFromJson(const nlohmann::json& j, const std::string& context);
std::vector<MountPlace> ReadMountsJson(const std::string& path);

struct OptimizeOptions {
  int num_cameras = 4;
  double grid_step_m = 0.5;  // grid of the search (a final evaluation uses the fine grid)
  int iterations = 2500;     // annealing steps per restart
  int restarts = 3;          // the first starts spread evenly, the others at random
  uint64_t seed = 1;
  double start_temperature = 0.02;  // in score units; cools geometrically to 1e-3 of it
  double move_step_m = 3.0;         // initial standard deviation of a move along a place (shrinks)
  double aim_step_m = 3.0;          // and of the aim point on the ground
  double aim_height_m = 0.0;        // height of the aim points
  bool progress = false;

  void Check() const;
};

struct OptimizeResult {
  Rig rig;
  double score = 0;        // of `rig` on the search grid
  double start_score = 0;  // of the first (evenly spread) start
  int evaluations = 0;
  double seconds = 0;
  std::string Summary() const;
};

// `model` gives the cameras' image size and intrinsics (its pose is ignored).
OptimizeResult OptimizeRig(const field::FieldModel& field, const std::vector<MountPlace>& mounts,
                           const camera::Camera& model, const CoverageOptions& coverage,
                           const OptimizeOptions& options);

// The score of `cameras` with the coverage options on a grid of `grid_step_m` (its layers').
double RigScore(const std::vector<camera::Camera>& cameras, const field::FieldModel& field,
                const CoverageOptions& coverage, double grid_step_m);

}  // namespace fv::plan
