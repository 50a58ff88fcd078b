// The built-in fields. Names: sides are "left" (x < 0) and "right" (x > 0); "top" is y > 0 and
// "bottom" y < 0 as seen in the top view. Lines are modelled by their centrelines; where a rule
// book measures to the outer edge of a line (FIFA, futsal, MSL, tennis) or to its inner edge
// (FIBA), the centreline is offset by half a line width accordingly.
#include <cmath>

#include <fmt/format.h>

#include "fieldvision/field/field.h"
#include "fieldvision/util/error.h"

namespace fv::field {
namespace {

const char* SideName(int s) { return s < 0 ? "left" : "right"; }
const char* YName(int t) { return t > 0 ? "top" : "bottom"; }

class Builder {
 public:
  explicit Builder(FieldModel* f) : f_(f) {}
  void Seg(const std::string& name, double x0, double y0, double x1, double y1, double w = 0) {
    f_->segments.push_back({name, {x0, y0}, {x1, y1}, w > 0 ? w : f_->line_width_m});
  }
  void Arc(const std::string& name, double cx, double cy, double r, double a0, double a1,
           double w = 0) {
    f_->arcs.push_back({name, {cx, cy}, r, a0, a1, w > 0 ? w : f_->line_width_m});
  }
  // A painted spot of the given diameter: a full circle whose paint covers the disc.
  void Spot(const std::string& name, double x, double y, double diameter) {
    Arc(name, x, y, diameter / 4, 0, 2 * M_PI, diameter / 2);
  }
  void Kp(const std::string& name, double x, double y, double z = 0) {
    f_->keypoints.push_back({name, {x, y, z}});
  }

 private:
  FieldModel* f_;
};

struct SoccerSpec {
  double length, width, line;
  double penalty_depth, penalty_width;                             // outer edge to outer edge
  double goal_area_depth, goal_area_width;                         // 0: none
  double centre_radius, corner_radius, penalty_mark, second_mark;  // 0: none
  double goal_width, goal_height, spot_diameter;
  bool futsal_area;           // quarter circles around the posts joined by a straight line
  double penalty_arc_radius;  // 0: none
};

FieldModel Soccer(const std::string& name, const std::string& description, const SoccerSpec& s,
                  double surround) {
  FieldModel f;
  f.name = name;
  f.description = description;
  f.length_m = s.length;
  f.width_m = s.width;
  f.line_width_m = s.line;
  f.surround_m = surround;
  f.surface = "grass";
  Builder b(&f);
  const double h = s.line / 2;
  const double L2 = s.length / 2 - h;  // centreline of the goal lines
  const double W2 = s.width / 2 - h;   // centreline of the touch lines
  b.Seg("touch_line_top", -L2, W2, L2, W2);
  b.Seg("touch_line_bottom", -L2, -W2, L2, -W2);
  b.Seg("halfway_line", 0, -W2, 0, W2);
  b.Arc("centre_circle", 0, 0, s.centre_radius - h, 0, 2 * M_PI);
  b.Spot("centre_spot", 0, 0, s.spot_diameter);
  b.Kp("centre_spot", 0, 0);
  b.Kp("halfway_top", 0, W2);
  b.Kp("halfway_bottom", 0, -W2);
  b.Kp("centre_circle_top", 0, s.centre_radius - h);
  b.Kp("centre_circle_bottom", 0, -(s.centre_radius - h));
  b.Kp("centre_circle_left", -(s.centre_radius - h), 0);
  b.Kp("centre_circle_right", s.centre_radius - h, 0);
  for (int side : {-1, 1}) {
    const std::string sn = SideName(side);
    b.Seg(fmt::format("goal_line_{}", sn), side * L2, -W2, side * L2, W2);
    for (int t : {-1, 1}) {
      const std::string tn = YName(t);
      b.Kp(fmt::format("corner_{}_{}", sn, tn), side * L2, t * W2);
      // Corner arc centred on the outer corner, inside the field.
      const double a0 = std::atan2(-t, -side);  // direction from the corner into the field
      b.Arc(fmt::format("corner_arc_{}_{}", sn, tn), side * s.length / 2, t * s.width / 2,
            s.corner_radius - h, a0 - M_PI / 4, a0 + M_PI / 4);
    }
    // Penalty area.
    const double xp = side * (s.length / 2 - s.penalty_depth + h);
    const double yp = s.penalty_width / 2 - h;
    if (!s.futsal_area) {
      b.Seg(fmt::format("penalty_area_{}_front", sn), xp, -yp, xp, yp);
      for (int t : {-1, 1}) {
        const std::string tn = YName(t);
        b.Seg(fmt::format("penalty_area_{}_{}", sn, tn), side * L2, t * yp, xp, t * yp);
        b.Kp(fmt::format("penalty_area_{}_{}_goal_line", sn, tn), side * L2, t * yp);
        b.Kp(fmt::format("penalty_area_{}_{}", sn, tn), xp, t * yp);
      }
    } else {
      // Futsal: quarter circles of radius penalty_depth around the outside of each post.
      const double yq = s.goal_width / 2 + s.line;
      const double r = s.penalty_depth - h;
      b.Seg(fmt::format("penalty_area_{}_front", sn), side * (L2 - r), -yq, side * (L2 - r), yq);
      for (int t : {-1, 1}) {
        const std::string tn = YName(t);
        // From the direction into the field (towards x = 0) to the direction of the touch line.
        const double into = side < 0 ? 0.0 : M_PI;
        const double towards = t > 0 ? M_PI / 2 : -M_PI / 2;
        double a0 = std::min(into, towards), a1 = std::max(into, towards);
        if (a1 - a0 > M_PI) std::swap(a0, a1), a1 += 2 * M_PI;
        b.Arc(fmt::format("penalty_area_{}_{}", sn, tn), side * L2, t * yq, r, a0, a1);
        b.Kp(fmt::format("penalty_area_{}_{}_goal_line", sn, tn), side * L2, t * (yq + r));
        b.Kp(fmt::format("penalty_area_{}_{}", sn, tn), side * (L2 - r), t * yq);
      }
    }
    if (s.goal_area_depth > 0) {
      const double xg = side * (s.length / 2 - s.goal_area_depth + h);
      const double yg = s.goal_area_width / 2 - h;
      b.Seg(fmt::format("goal_area_{}_front", sn), xg, -yg, xg, yg);
      for (int t : {-1, 1}) {
        const std::string tn = YName(t);
        b.Seg(fmt::format("goal_area_{}_{}", sn, tn), side * L2, t * yg, xg, t * yg);
        b.Kp(fmt::format("goal_area_{}_{}_goal_line", sn, tn), side * L2, t * yg);
        b.Kp(fmt::format("goal_area_{}_{}", sn, tn), xg, t * yg);
      }
    }
    const double xm = side * (s.length / 2 - s.penalty_mark);
    b.Spot(fmt::format("penalty_mark_{}", sn), xm, 0, s.spot_diameter);
    b.Kp(fmt::format("penalty_mark_{}", sn), xm, 0);
    if (s.second_mark > 0) {
      const double x2 = side * (s.length / 2 - s.second_mark);
      b.Spot(fmt::format("second_penalty_mark_{}", sn), x2, 0, s.spot_diameter);
      b.Kp(fmt::format("second_penalty_mark_{}", sn), x2, 0);
    }
    if (s.penalty_arc_radius > 0) {
      const double r = s.penalty_arc_radius - h;
      const double dx = std::abs(xp - xm);
      if (dx < r) {
        const double theta = std::acos(dx / r);
        const double dir = side < 0 ? 0.0 : M_PI;
        b.Arc(fmt::format("penalty_arc_{}", sn), xm, 0, r, dir - theta, dir + theta);
      }
    }
    FieldGoal g;
    g.name = fmt::format("goal_{}", sn);
    g.side = side;
    g.line_x_m = side * L2;
    g.y_min_m = -s.goal_width / 2;
    g.y_max_m = s.goal_width / 2;
    g.height_m = s.goal_height;
    g.post_width_m = s.line;
    g.depth_m = std::max(0.5, s.goal_height * 0.8);
    f.goals.push_back(g);
    for (int t : {-1, 1}) {
      const std::string tn = YName(t);
      const double yp_post = t * (s.goal_width / 2 + h);
      b.Kp(fmt::format("goal_{}_post_{}", sn, tn), side * L2, yp_post, 0);
      b.Kp(fmt::format("goal_{}_post_{}_high", sn, tn), side * L2, yp_post, s.goal_height);
    }
  }
  f.Check();
  return f;
}

FieldModel Basketball() {
  FieldModel f;
  f.name = "basketball-fiba";
  f.description = "FIBA basketball court, 28 x 15 m to the inner edges of the boundary lines";
  f.length_m = 28.0;
  f.width_m = 15.0;
  f.line_width_m = 0.05;
  f.surround_m = 2.0;
  f.surface = "court";
  Builder b(&f);
  const double h = 0.025;
  const double L2 = 14.0 + h, W2 = 7.5 + h;  // boundary lines lie outside the court
  b.Seg("side_line_top", -L2, W2, L2, W2);
  b.Seg("side_line_bottom", -L2, -W2, L2, -W2);
  b.Seg("centre_line", 0, -W2, 0, W2);
  b.Arc("centre_circle", 0, 0, 1.80 - h, 0, 2 * M_PI);
  b.Kp("centre", 0, 0);
  b.Kp("centre_line_top", 0, W2);
  b.Kp("centre_line_bottom", 0, -W2);
  b.Kp("centre_circle_left", -(1.80 - h), 0);
  b.Kp("centre_circle_right", 1.80 - h, 0);
  for (int side : {-1, 1}) {
    const std::string sn = SideName(side);
    b.Seg(fmt::format("end_line_{}", sn), side * L2, -W2, side * L2, W2);
    const double xb = side * (14.0 - 1.575);  // below the basket centre
    // Restricted area: 4.90 m wide (outer edges), free-throw line's far edge 5.80 m from the
    // end line's inner edge.
    const double yk = 2.45 - h;
    const double xf = side * (14.0 - 5.80 + h);
    b.Seg(fmt::format("free_throw_line_{}", sn), xf, -yk, xf, yk);
    b.Arc(fmt::format("free_throw_circle_{}", sn), xf, 0, 1.80 - h, side < 0 ? -M_PI / 2 : M_PI / 2,
          side < 0 ? M_PI / 2 : 3 * M_PI / 2);
    b.Kp(fmt::format("free_throw_{}_centre", sn), xf, 0);
    b.Kp(fmt::format("free_throw_circle_{}", sn), xf - side * (1.80 - h), 0);
    // Three-point line: arc of 6.75 m (outer edge) around the basket, straight parts 0.90 m from
    // the side lines' inner edges.
    const double r3 = 6.75 - h;
    const double y3 = 7.5 - 0.90 - h;
    const double dx3 = std::sqrt(r3 * r3 - y3 * y3);
    const double theta = std::atan2(y3, dx3);
    const double dir = side < 0 ? 0.0 : M_PI;
    b.Arc(fmt::format("three_point_arc_{}", sn), xb, 0, r3, dir - theta, dir + theta);
    b.Kp(fmt::format("three_point_{}_centre", sn), xb - side * r3, 0);
    // No-charge semicircle: 1.25 m to its inner edge.
    b.Arc(fmt::format("no_charge_{}", sn), xb, 0, 1.25 + h, dir - M_PI / 2, dir + M_PI / 2);
    for (int t : {-1, 1}) {
      const std::string tn = YName(t);
      b.Kp(fmt::format("corner_{}_{}", sn, tn), side * L2, t * W2);
      b.Seg(fmt::format("restricted_area_{}_{}", sn, tn), side * L2, t * yk, xf, t * yk);
      b.Kp(fmt::format("restricted_area_{}_{}_end_line", sn, tn), side * L2, t * yk);
      b.Kp(fmt::format("restricted_area_{}_{}", sn, tn), xf, t * yk);
      b.Seg(fmt::format("three_point_{}_{}", sn, tn), side * L2, t * y3, xb - side * dx3, t * y3);
      b.Kp(fmt::format("three_point_{}_{}_end_line", sn, tn), side * L2, t * y3);
      b.Kp(fmt::format("three_point_{}_{}", sn, tn), xb - side * dx3, t * y3);
    }
    FieldHoop hoop;
    hoop.name = fmt::format("hoop_{}", sn);
    hoop.centre_m = {xb, 0, 3.05};
    hoop.radius_m = 0.225;
    f.hoops.push_back(hoop);
    b.Kp(fmt::format("hoop_{}", sn), xb, 0, 3.05);
    b.Kp(fmt::format("basket_{}_floor", sn), xb, 0, 0);
  }
  f.Check();
  return f;
}

FieldModel Tennis() {
  FieldModel f;
  f.name = "tennis";
  f.description = "ITF tennis court, 23.77 x 10.97 m (doubles) to the outer edges of the lines";
  f.length_m = 23.77;
  f.width_m = 10.97;
  f.line_width_m = 0.05;
  f.surround_m = 4.0;
  f.surface = "court";
  Builder b(&f);
  const double h = 0.025;
  const double xb = 11.885 - 0.05;  // baselines are 0.10 m wide
  const double yd = 5.485 - h;
  const double ys = 4.115 - h;
  const double xs = 6.40 - h;
  for (int t : {-1, 1}) {
    const std::string tn = YName(t);
    b.Seg(fmt::format("doubles_side_line_{}", tn), -xb, t * yd, xb, t * yd);
    b.Seg(fmt::format("singles_side_line_{}", tn), -xb, t * ys, xb, t * ys);
    b.Kp(fmt::format("net_post_{}", tn), 0, t * (5.485 + 0.914), 1.07);
    b.Kp(fmt::format("net_{}_doubles", tn), 0, t * yd, 0);
  }
  b.Seg("centre_service_line", -xs, 0, xs, 0);
  b.Kp("net_centre", 0, 0, 0.914);
  b.Kp("net_centre_ground", 0, 0, 0);
  for (int side : {-1, 1}) {
    const std::string sn = SideName(side);
    b.Seg(fmt::format("baseline_{}", sn), side * xb, -yd, side * xb, yd, 0.10);
    b.Seg(fmt::format("service_line_{}", sn), side * xs, -ys, side * xs, ys);
    b.Seg(fmt::format("centre_mark_{}", sn), side * xb, 0, side * (11.885 - 0.10 - 0.10), 0);
    b.Kp(fmt::format("centre_mark_{}", sn), side * xb, 0);
    b.Kp(fmt::format("service_{}_centre", sn), side * xs, 0);
    for (int t : {-1, 1}) {
      const std::string tn = YName(t);
      b.Kp(fmt::format("corner_{}_{}", sn, tn), side * xb, t * yd);
      b.Kp(fmt::format("singles_corner_{}_{}", sn, tn), side * xb, t * ys);
      b.Kp(fmt::format("service_{}_{}", sn, tn), side * xs, t * ys);
    }
  }
  f.Check();
  return f;
}

// ITTF table (Handbook, law 2.1): playing surface 2.74 x 1.525 m, 2 cm white edge lines, a 3 mm
// centre line for doubles, the net 15.25 cm high over the middle, its posts 15.25 cm outside the
// side lines. The "ground" is the table surface (z = 0), as in the TT3D recordings.
FieldModel TableTennis() {
  FieldModel f;
  f.name = "table-tennis";
  f.description =
      "ITTF table-tennis table, 2.74 x 1.525 m playing surface (z = 0 on the table), net 15.25 cm";
  f.length_m = 2.74;
  f.width_m = 1.525;
  f.line_width_m = 0.02;
  f.surround_m = 1.5;
  f.surface = "court";
  Builder b(&f);
  const double xe = 1.37 - 0.01, ye = 0.7625 - 0.01;  // centrelines of the 2 cm edge lines
  for (int t : {-1, 1}) {
    const std::string tn = YName(t);
    b.Seg(fmt::format("side_line_{}", tn), -1.37, t * ye, 1.37, t * ye);
    b.Kp(fmt::format("net_post_{}", tn), 0, t * (0.7625 + 0.1525), 0.1525);
    b.Kp(fmt::format("net_{}", tn), 0, t * 0.7625, 0);
    b.Kp(fmt::format("net_top_{}", tn), 0, t * 0.7625, 0.1525);
  }
  b.Kp("net_top_centre", 0, 0, 0.1525);
  b.Seg("centre_line", -1.37, 0, 1.37, 0, 0.003);
  for (int side : {-1, 1}) {
    const std::string sn = SideName(side);
    b.Seg(fmt::format("end_line_{}", sn), side * xe, -0.7625, side * xe, 0.7625);
    b.Kp(fmt::format("centre_line_end_{}", sn), side * 1.37, 0);
    for (int t : {-1, 1}) b.Kp(fmt::format("corner_{}_", sn) + YName(t), side * 1.37, t * 0.7625);
  }
  f.Check();
  return f;
}

}  // namespace

std::vector<std::string> BuiltinFieldNames() {
  return {"robocup-msl", "fifa", "futsal", "basketball-fiba", "tennis", "table-tennis"};
}

FieldModel BuiltinField(const std::string& name) {
  if (name == "fifa") {
    SoccerSpec s{105.0, 68.0, 0.12, 16.5, 40.32, 5.5,  18.32, 9.15,
                 1.0,   11.0, 0.0,  7.32, 2.44,  0.22, false, 9.15};
    return Soccer(name, "FIFA football pitch, 105 x 68 m (Laws of the Game, law 1)", s, 5.0);
  }
  if (name == "robocup-msl") {
    SoccerSpec s{18.0, 12.0, 0.125, 2.25, 6.5, 0.75, 3.5,   2.0,
                 0.75, 3.0,  0.0,   2.0,  1.0, 0.15, false, 0.0};
    return Soccer(name, "RoboCup Middle Size League field, 18 x 12 m, 0.125 m lines", s, 1.5);
  }
  if (name == "futsal") {
    SoccerSpec s{40.0, 20.0, 0.08, 6.0, 0.0, 0.0,  0.0,  3.0,
                 0.25, 6.0,  10.0, 3.0, 2.0, 0.12, true, 0.0};
    return Soccer(name, "Futsal pitch, 40 x 20 m (Futsal Laws of the Game)", s, 2.0);
  }
  if (name == "basketball-fiba") return Basketball();
  if (name == "tennis") return Tennis();
  if (name == "table-tennis") return TableTennis();
  std::string list;
  for (const auto& n : BuiltinFieldNames()) list += (list.empty() ? "" : ", ") + n;
  Throw("unknown field '{}': give a JSON file or one of {}", name, list);
}

}  // namespace fv::field
