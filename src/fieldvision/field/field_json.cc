#include "fieldvision/field/field_json.h"

#include <filesystem>
#include <fstream>

#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"

namespace fv::field {
namespace {

using nlohmann::json;

// A number under `key`; without it `fallback`, or an error when `required`.
double Num(const json& obj, const char* key, const std::string& ctx, double fallback = NAN,
           bool required = true) {
  return required ? util::JsonNumber(obj, key, ctx) : util::JsonNumber(obj, key, ctx, fallback);
}

std::string Str(const json& obj, const char* key, const std::string& ctx,
                const std::string& fallback = "") {
  return util::JsonString(obj, key, ctx, fallback);
}

}  // namespace

json FieldToJson(const FieldModel& f) {
  json j;
  j["name"] = f.name;
  j["description"] = f.description;
  j["length_m"] = f.length_m;
  j["width_m"] = f.width_m;
  j["line_width_m"] = f.line_width_m;
  j["surround_m"] = f.surround_m;
  j["surface"] = f.surface;
  j["segments"] = json::array();
  for (const auto& s : f.segments) {
    j["segments"].push_back({{"name", s.name},
                             {"a", util::JsonFromVector(s.a)},
                             {"b", util::JsonFromVector(s.b)},
                             {"width_m", s.width_m}});
  }
  j["arcs"] = json::array();
  for (const auto& a : f.arcs) {
    j["arcs"].push_back({{"name", a.name},
                         {"centre", util::JsonFromVector(a.centre)},
                         {"radius_m", a.radius_m},
                         {"start_rad", a.start_rad},
                         {"end_rad", a.end_rad},
                         {"width_m", a.width_m}});
  }
  j["keypoints"] = json::array();
  for (const auto& k : f.keypoints) {
    j["keypoints"].push_back(
        {{"name", k.name}, {"position_m", util::JsonFromVector(k.position_m)}});
  }
  j["goals"] = json::array();
  for (const auto& g : f.goals) {
    j["goals"].push_back({{"name", g.name},
                          {"side", g.side},
                          {"line_x_m", g.line_x_m},
                          {"y_min_m", g.y_min_m},
                          {"y_max_m", g.y_max_m},
                          {"height_m", g.height_m},
                          {"post_width_m", g.post_width_m},
                          {"depth_m", g.depth_m}});
  }
  j["hoops"] = json::array();
  for (const auto& h : f.hoops) {
    j["hoops"].push_back({{"name", h.name},
                          {"centre_m", util::JsonFromVector(h.centre_m)},
                          {"radius_m", h.radius_m}});
  }
  return j;
}

FieldModel FieldFromJson(const json& j, const std::string& ctx) {
  FV_REQUIRE(j.is_object(), "{}: a field must be a JSON object", ctx);
  FieldModel f;
  f.name = Str(j, "name", ctx, "custom");
  f.description = Str(j, "description", ctx);
  f.length_m = Num(j, "length_m", ctx);
  f.width_m = Num(j, "width_m", ctx);
  f.line_width_m = Num(j, "line_width_m", ctx, 0.1, false);
  f.surround_m = Num(j, "surround_m", ctx, 2.0, false);
  f.surface = Str(j, "surface", ctx, "grass");
  for (size_t i = 0; i < util::JsonArray(j, "segments", ctx).size(); ++i) {
    const json& s = j["segments"][i];
    const std::string c = fmt::format("{}: segments[{}]", ctx, i);
    FV_REQUIRE(s.is_object(), "{}: must be an object", c);
    f.segments.push_back({Str(s, "name", c), util::JsonVector<2>(s, "a", c),
                          util::JsonVector<2>(s, "b", c),
                          Num(s, "width_m", c, f.line_width_m, false)});
  }
  for (size_t i = 0; i < util::JsonArray(j, "arcs", ctx).size(); ++i) {
    const json& a = j["arcs"][i];
    const std::string c = fmt::format("{}: arcs[{}]", ctx, i);
    FV_REQUIRE(a.is_object(), "{}: must be an object", c);
    f.arcs.push_back({Str(a, "name", c), util::JsonVector<2>(a, "centre", c), Num(a, "radius_m", c),
                      Num(a, "start_rad", c, 0.0, false), Num(a, "end_rad", c, 2 * M_PI, false),
                      Num(a, "width_m", c, f.line_width_m, false)});
  }
  for (size_t i = 0; i < util::JsonArray(j, "keypoints", ctx).size(); ++i) {
    const json& k = j["keypoints"][i];
    const std::string c = fmt::format("{}: keypoints[{}]", ctx, i);
    FV_REQUIRE(k.is_object(), "{}: must be an object", c);
    f.keypoints.push_back({Str(k, "name", c), util::JsonVector<3>(k, "position_m", c)});
  }
  for (size_t i = 0; i < util::JsonArray(j, "goals", ctx).size(); ++i) {
    const json& g = j["goals"][i];
    const std::string c = fmt::format("{}: goals[{}]", ctx, i);
    FieldGoal goal;
    goal.name = Str(g, "name", c);
    goal.side = static_cast<int>(Num(g, "side", c));
    goal.line_x_m = Num(g, "line_x_m", c);
    goal.y_min_m = Num(g, "y_min_m", c);
    goal.y_max_m = Num(g, "y_max_m", c);
    goal.height_m = Num(g, "height_m", c);
    goal.post_width_m = Num(g, "post_width_m", c, 0.1, false);
    goal.depth_m = Num(g, "depth_m", c, 0.5, false);
    f.goals.push_back(goal);
  }
  for (size_t i = 0; i < util::JsonArray(j, "hoops", ctx).size(); ++i) {
    const json& h = j["hoops"][i];
    const std::string c = fmt::format("{}: hoops[{}]", ctx, i);
    f.hoops.push_back({Str(h, "name", c), util::JsonVector<3>(h, "centre_m", c),
                       Num(h, "radius_m", c, 0.225, false)});
  }
  try {
    f.Check();
  } catch (const Error& e) {
    Throw("{}: {}", ctx, e.what());
  }
  return f;
}

FieldModel ReadFieldJson(const std::string& path) {
  FV_REQUIRE(std::filesystem::is_regular_file(path), "field file '{}' does not exist", path);
  std::ifstream in(path);
  FV_REQUIRE(in.good(), "cannot open field file '{}'", path);
  json j;
  try {
    in >> j;
  } catch (const json::exception& e) {
    Throw("field file '{}' is not valid JSON ({})", path, e.what());
  }
  return FieldFromJson(j, "field file '" + path + "'");
}

void WriteFieldJson(const FieldModel& field, const std::string& path) {
  std::ofstream out(path);
  FV_REQUIRE(out.good(), "cannot write field file '{}'", path);
  out << FieldToJson(field).dump(2) << '\n';
  FV_REQUIRE(out.good(), "error while writing field file '{}'", path);
}

}  // namespace fv::field
