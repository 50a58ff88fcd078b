#include "fieldvision/field/field.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include "fieldvision/field/field_json.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::field {

double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double DistanceToArc(const Eigen::Vector2d& p, const FieldArc& arc) {
  const Eigen::Vector2d d = p - arc.centre;
  double angle = std::atan2(d.y(), d.x());
  // Bring the angle into [start, start + 2 pi).
  while (angle < arc.start_rad) angle += 2 * M_PI;
  while (angle >= arc.start_rad + 2 * M_PI) angle -= 2 * M_PI;
  if (angle <= arc.end_rad) return std::abs(d.norm() - arc.radius_m);
  auto end_point = [&](double a) {
    return Eigen::Vector2d(arc.centre + arc.radius_m * Eigen::Vector2d(std::cos(a), std::sin(a)));
  };
  return std::min((p - end_point(arc.start_rad)).norm(), (p - end_point(arc.end_rad)).norm());
}

void FieldModel::Check() const {
  const std::string ctx = "field '" + name + "'";
  CheckPositive(length_m, (ctx + " length_m").c_str());
  CheckPositive(width_m, (ctx + " width_m").c_str());
  CheckPositive(line_width_m, (ctx + " line_width_m").c_str());
  CheckNonNegative(surround_m, (ctx + " surround_m").c_str());
  // Sizes a sports ground can have (maps, grids and heat maps are sized from them).
  constexpr double kMaxSideM = 1000.0, kMaxAspect = 20.0;
  FV_REQUIRE(length_m <= kMaxSideM && width_m <= kMaxSideM && surround_m <= kMaxSideM &&
                 line_width_m <= std::min(length_m, width_m),
             "{}: {} x {} m with {} m lines and a {} m surround is not a field (sides and "
             "surround at most {:.0f} m, lines narrower than the field)",
             ctx, length_m, width_m, line_width_m, surround_m, kMaxSideM);
  FV_REQUIRE(std::max(length_m, width_m) <= kMaxAspect * std::min(length_m, width_m),
             "{}: {} x {} m: one side is more than {:.0f} times the other", ctx, length_m, width_m,
             kMaxAspect);
  // Everything painted or named lies within the largest field's reach of its centre.
  auto within = [&](double metres) { return std::abs(metres) <= kMaxSideM; };
  for (const auto& s : segments) {
    FV_REQUIRE(s.a.allFinite() && s.b.allFinite() && std::isfinite(s.width_m) && s.width_m > 0,
               "{}: line '{}' has a non-finite end or a bad width", ctx, s.name);
    FV_REQUIRE(s.a.cwiseAbs().maxCoeff() <= kMaxSideM && s.b.cwiseAbs().maxCoeff() <= kMaxSideM &&
                   s.width_m <= kMaxSideM,
               "{}: line '{}' reaches more than {:.0f} m from the centre", ctx, s.name, kMaxSideM);
  }
  for (const auto& a : arcs) {
    FV_REQUIRE(a.centre.allFinite() && std::isfinite(a.radius_m) && a.radius_m > 0 &&
                   std::isfinite(a.start_rad) && std::isfinite(a.end_rad) &&
                   a.end_rad > a.start_rad && a.end_rad - a.start_rad <= 2 * M_PI + 1e-9 &&
                   a.width_m > 0,
               "{}: arc '{}' needs a finite centre, radius > 0 and start_rad < end_rad <= "
               "start_rad + 2 pi",
               ctx, a.name);
    FV_REQUIRE(a.centre.cwiseAbs().maxCoeff() + a.radius_m <= kMaxSideM && a.width_m <= kMaxSideM,
               "{}: arc '{}' reaches more than {:.0f} m from the centre", ctx, a.name, kMaxSideM);
  }
  std::set<std::string> names;
  for (const auto& k : keypoints) {
    FV_REQUIRE(!k.name.empty(), "{}: a keypoint has no name", ctx);
    FV_REQUIRE(k.position_m.allFinite(), "{}: keypoint '{}' is not finite", ctx, k.name);
    FV_REQUIRE(k.position_m.cwiseAbs().maxCoeff() <= kMaxSideM,
               "{}: keypoint '{}' lies more than {:.0f} m from the centre", ctx, k.name, kMaxSideM);
    FV_REQUIRE(names.insert(k.name).second, "{}: keypoint '{}' is listed twice", ctx, k.name);
  }
  for (const auto& g : goals) {
    FV_REQUIRE(g.y_max_m > g.y_min_m && g.height_m > 0 && (g.side == -1 || g.side == 1),
               "{}: goal '{}' needs y_max_m > y_min_m, height_m > 0 and side -1 or 1", ctx, g.name);
    FV_REQUIRE(within(g.line_x_m) && within(g.y_min_m) && within(g.y_max_m) && within(g.height_m) &&
                   within(g.depth_m),
               "{}: goal '{}' reaches more than {:.0f} m from the centre", ctx, g.name, kMaxSideM);
  }
  for (const auto& h : hoops) {
    FV_REQUIRE(h.centre_m.allFinite() && h.centre_m.cwiseAbs().maxCoeff() <= kMaxSideM &&
                   std::isfinite(h.radius_m) && h.radius_m > 0 && h.radius_m <= kMaxSideM,
               "{}: hoop '{}' needs a centre within {:.0f} m of the field's and a radius > 0", ctx,
               h.name, kMaxSideM);
  }
}

const FieldKeypoint* FieldModel::FindKeypoint(const std::string& key) const {
  for (const auto& k : keypoints) {
    if (k.name == key) return &k;
  }
  return nullptr;
}

double FieldModel::DistanceToLineCentres(const Eigen::Vector2d& p) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& s : segments) best = std::min(best, DistanceToSegment(p, s.a, s.b));
  for (const auto& a : arcs) best = std::min(best, DistanceToArc(p, a));
  return best;
}

double FieldModel::DistanceToPaint(const Eigen::Vector2d& p) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& s : segments) {
    best = std::min(best, DistanceToSegment(p, s.a, s.b) - 0.5 * s.width_m);
  }
  for (const auto& a : arcs) best = std::min(best, DistanceToArc(p, a) - 0.5 * a.width_m);
  return best;
}

std::vector<Eigen::Vector2d> FieldModel::SampleLines(double step_m) const {
  FV_REQUIRE(step_m > 0, "SampleLines: step_m must be > 0");
  std::vector<Eigen::Vector2d> out;
  for (const auto& s : segments) {
    const int n = std::max(1, static_cast<int>(std::ceil((s.b - s.a).norm() / step_m)));
    for (int i = 0; i <= n; ++i) out.push_back(s.a + (s.b - s.a) * (static_cast<double>(i) / n));
  }
  for (const auto& a : arcs) {
    const double len = a.radius_m * (a.end_rad - a.start_rad);
    const int n = std::max(1, static_cast<int>(std::ceil(len / step_m)));
    for (int i = 0; i <= n; ++i) {
      const double t = a.start_rad + (a.end_rad - a.start_rad) * i / n;
      out.push_back(a.centre + a.radius_m * Eigen::Vector2d(std::cos(t), std::sin(t)));
    }
  }
  return out;
}

FieldModel LoadField(const std::string& name_or_path) {
  const auto names = BuiltinFieldNames();
  if (std::find(names.begin(), names.end(), name_or_path) != names.end()) {
    return BuiltinField(name_or_path);
  }
  if (util::EndsWith(util::ToLower(name_or_path), ".json") ||
      std::filesystem::exists(name_or_path)) {
    return ReadFieldJson(name_or_path);
  }
  return BuiltinField(name_or_path);  // throws with the list of names
}

}  // namespace fv::field
