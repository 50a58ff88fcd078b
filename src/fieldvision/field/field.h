// Models of sports fields: painted lines (segments and arcs with widths), named keypoints, goals
// and hoops, in world metres (origin at the centre, x along the length, z up). Built-in fields
// follow the rule books (FIFA Laws of the Game, RoboCup MSL rules, FIBA, ITF); custom fields
// are JSON files of the same structure (field_json.h).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace fv::field {

// A straight painted line; a and b are the ends of its centreline.
struct FieldSegment {
  std::string name;
  Eigen::Vector2d a = Eigen::Vector2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  double width_m = 0.1;
};

// A painted arc: the centreline is the circle (centre, radius_m) from start_rad to end_rad,
// counter-clockwise (end_rad > start_rad; 2*pi apart for a full circle).
struct FieldArc {
  std::string name;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius_m = 1.0;
  double start_rad = 0.0;
  double end_rad = 0.0;
  double width_m = 0.1;
};

struct FieldKeypoint {
  std::string name;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
};

// A goal on a goal line x = line_x_m, open between post inner faces y_min_m..y_max_m, the bar's
// underside at height_m. side is -1 for the goal at x < 0, +1 for x > 0.
struct FieldGoal {
  std::string name;
  int side = -1;
  double line_x_m = 0.0;
  double y_min_m = 0.0;
  double y_max_m = 0.0;
  double height_m = 0.0;
  double post_width_m = 0.1;
  double depth_m = 0.5;
};

// A basketball ring: centre and inner radius, horizontal.
struct FieldHoop {
  std::string name;
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  double radius_m = 0.225;
};

struct FieldModel {
  std::string name;
  std::string description;
  double length_m = 0.0;  // rule-book dimensions of the playing area
  double width_m = 0.0;
  double line_width_m = 0.1;
  double surround_m = 2.0;        // run-off area around the playing area (walls stand beyond it)
  std::string surface = "grass";  // "grass" or "court": a hint for rendering
  std::vector<FieldSegment> segments;
  std::vector<FieldArc> arcs;
  std::vector<FieldKeypoint> keypoints;
  std::vector<FieldGoal> goals;
  std::vector<FieldHoop> hoops;

  // Throws fv::Error naming the problem (non-positive size, NaN, duplicate keypoint names...).
  void Check() const;
  const FieldKeypoint* FindKeypoint(const std::string& name) const;
  // Distance from p to the nearest line centreline (segments and arcs).
  double DistanceToLineCentres(const Eigen::Vector2d& p) const;
  // Whether the field has painted lines (segments or arcs) to fit a camera's pose to.
  bool HasPaintedLines() const { return !segments.empty() || !arcs.empty(); }
  // Signed distance to the nearest painted area: < 0 inside the paint.
  double DistanceToPaint(const Eigen::Vector2d& p) const;
  // Points along every line centreline, about step_m apart (ends included).
  std::vector<Eigen::Vector2d> SampleLines(double step_m) const;
  // Half-extents of the area drawn or rendered: playing area plus the surround.
  double HalfLengthWithSurround() const { return 0.5 * length_m + surround_m; }
  double HalfWidthWithSurround() const { return 0.5 * width_m + surround_m; }
};

double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b);
double DistanceToArc(const Eigen::Vector2d& p, const FieldArc& arc);

// Names of the built-in fields: robocup-msl, fifa, futsal, basketball-fiba, tennis.
std::vector<std::string> BuiltinFieldNames();
// Throws fv::Error listing the names when `name` is not one of them.
FieldModel BuiltinField(const std::string& name);
// A built-in name or the path of a field JSON file.
FieldModel LoadField(const std::string& name_or_path);

}  // namespace fv::field
