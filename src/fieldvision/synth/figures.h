// Moving bodies of the synthetic world as analytic primitives: motion along waypoint paths (back
// and forth, per-leg speeds, a continuous gait phase), articulated people (legs, arms, torso,
// pelvis as capsules, head as a sphere; the gait swings limbs and bends knees and elbows), robots
// as closed vertical cylinders; with ray intersection (capsule after I. Quilez, "Capsule - ray
// intersection", iquilezles.org) returning depth, normal and colour.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "fieldvision/synth/synth.h"

namespace fv::synth {

struct PathState {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d heading = Eigen::Vector2d(1, 0);  // unit direction of motion (or last one)
  double speed_mps = 0.0;
  double gait_cycles = 0.0;  // stride cycles walked so far
};

// Where a path puts its walker at time_s. stride_m(speed) gives the stride length for the gait.
PathState PathAt(const PathSpec& path, double time_s);

// A capsule (segment a-b, radius) coloured colour_a for axis parameter < split, else colour_b.
// A sphere is a capsule with a == b; `hair` colours its top hair_bgr.
struct Capsule {
  Eigen::Vector3d a, b;
  double radius_m = 0.05;
  Eigen::Vector3d colour_a, colour_b;
  double split = 1.0;
  bool hair = false;
};

// A closed vertical cylinder on the ground.
struct Cylinder {
  Eigen::Vector2d centre_m;
  double radius_m = 0.25, height_m = 0.8;
  Eigen::Vector3d side_bgr, top_bgr;
};

// A body: its primitives and a world bounding box.
struct Body {
  int id = 0;  // person id, or -1 - index for robots
  std::vector<Capsule> capsules;
  std::vector<Cylinder> cylinders;
  Eigen::Vector3d box_min, box_max;
  Eigen::Vector2d ground_xy = Eigen::Vector2d::Zero();
};

struct Hit {
  double t = -1;  // distance along the ray; < 0: no hit
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d colour = Eigen::Vector3d::Zero();
};

Body PersonBody(const PersonSpec& person, const TeamSpec& team, double time_s);
// A robot; with a handler its two arms are sized for a ball of ball_radius_m.
Body RobotBody(const RobotSpec& robot, int index, double time_s, double ball_radius_m = 0.11);
// Where a robot's handler holds a ball of that radius (centre, world).
Eigen::Vector3d HeldBallCentre(const RobotSpec& robot, double ball_radius_m, double time_s);

// Nearest intersection of the ray (origin, unit direction) with a body (t > t_min).
Hit IntersectBody(const Body& body, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                  double t_min = 1e-6);
// Whether the ray hits the body at all (for shadows).
bool RayHitsBody(const Body& body, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir);
// Primitive by primitive (capsules first, then cylinders), for renderers that rasterise each
// primitive only inside its own image box.
int NumPrimitives(const Body& body);
void PrimitiveBounds(const Body& body, int index, Eigen::Vector3d* lo, Eigen::Vector3d* hi);
double IntersectPrimitive(const Body& body, int index, const Eigen::Vector3d& origin,
                          const Eigen::Vector3d& dir);
// Normal and colour where the ray meets primitive `index` at distance t.
Hit ShadePrimitive(const Body& body, int index, const Eigen::Vector3d& origin,
                   const Eigen::Vector3d& dir, double t);
// Capsule and cone intersections (t along the ray, < 0 when missed).
double IntersectCapsule(const Eigen::Vector3d& ro, const Eigen::Vector3d& rd,
                        const Eigen::Vector3d& pa, const Eigen::Vector3d& pb, double radius);
// A cone with its base on z = 0 (circle of base_radius around apex_xy) and apex at height.
double IntersectCone(const Eigen::Vector3d& ro, const Eigen::Vector3d& rd,
                     const Eigen::Vector2d& apex_xy, double base_radius, double height,
                     Eigen::Vector3d* normal);

}  // namespace fv::synth
