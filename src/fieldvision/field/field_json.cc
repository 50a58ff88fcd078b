#include "fieldvision/field/field_json.h"

#include <filesystem>
#include <fstream>

#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"

namespace fv::field {

using nlohmann::json;

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
  f.name = util::JsonString(j, "name", ctx, "custom");
  f.description = util::JsonString(j, "description", ctx, "");
  f.length_m = util::JsonNumber(j, "length_m", ctx);
  f.width_m = util::JsonNumber(j, "width_m", ctx);
  f.line_width_m = util::JsonNumber(j, "line_width_m", ctx, 0.1);
  f.surround_m = util::JsonNumber(j, "surround_m", ctx, 2.0);
  f.surface = util::JsonString(j, "surface", ctx, "grass");
  for (size_t i = 0; i < util::JsonArray(j, "segments", ctx).size(); ++i) {
    const json& s = j["segments"][i];
    const std::string c = fmt::format("{}: segments[{}]", ctx, i);
    FV_REQUIRE(s.is_object(), "{}: must be an object", c);
    f.segments.push_back({util::JsonString(s, "name", c, ""), util::JsonVector<2>(s, "a", c),
                          util::JsonVector<2>(s, "b", c),
                          util::JsonNumber(s, "width_m", c, f.line_width_m)});
  }
  for (size_t i = 0; i < util::JsonArray(j, "arcs", ctx).size(); ++i) {
    const json& a = j["arcs"][i];
    const std::string c = fmt::format("{}: arcs[{}]", ctx, i);
    FV_REQUIRE(a.is_object(), "{}: must be an object", c);
    f.arcs.push_back({util::JsonString(a, "name", c, ""), util::JsonVector<2>(a, "centre", c),
                      util::JsonNumber(a, "radius_m", c), util::JsonNumber(a, "start_rad", c, 0.0),
                      util::JsonNumber(a, "end_rad", c, 2 * M_PI),
                      util::JsonNumber(a, "width_m", c, f.line_width_m)});
  }
  for (size_t i = 0; i < util::JsonArray(j, "keypoints", ctx).size(); ++i) {
    const json& k = j["keypoints"][i];
    const std::string c = fmt::format("{}: keypoints[{}]", ctx, i);
    FV_REQUIRE(k.is_object(), "{}: must be an object", c);
    f.keypoints.push_back(
        {util::JsonString(k, "name", c, ""), util::JsonVector<3>(k, "position_m", c)});
  }
  for (size_t i = 0; i < util::JsonArray(j, "goals", ctx).size(); ++i) {
    const json& g = j["goals"][i];
    const std::string c = fmt::format("{}: goals[{}]", ctx, i);
    FieldGoal goal;
    goal.name = util::JsonString(g, "name", c, "");
    goal.side = static_cast<int>(util::JsonNumber(g, "side", c));
    goal.line_x_m = util::JsonNumber(g, "line_x_m", c);
    goal.y_min_m = util::JsonNumber(g, "y_min_m", c);
    goal.y_max_m = util::JsonNumber(g, "y_max_m", c);
    goal.height_m = util::JsonNumber(g, "height_m", c);
    goal.post_width_m = util::JsonNumber(g, "post_width_m", c, 0.1);
    goal.depth_m = util::JsonNumber(g, "depth_m", c, 0.5);
    f.goals.push_back(goal);
  }
  for (size_t i = 0; i < util::JsonArray(j, "hoops", ctx).size(); ++i) {
    const json& h = j["hoops"][i];
    const std::string c = fmt::format("{}: hoops[{}]", ctx, i);
    f.hoops.push_back({util::JsonString(h, "name", c, ""), util::JsonVector<3>(h, "centre_m", c),
                       util::JsonNumber(h, "radius_m", c, 0.225)});
  }
  try {
    f.Check();
  } catch (const Error& e) {
    Throw("{}: {}", ctx, e.what());
  }
  return f;
}

FieldModel ReadFieldJson(const std::string& path) {
  return FieldFromJson(util::ReadJsonFile(path, "field"), "field file '" + path + "'");
}

void WriteFieldJson(const FieldModel& field, const std::string& path) {
  std::ofstream out(path);
  FV_REQUIRE(out.good(), "cannot write field file '{}'", path);
  out << FieldToJson(field).dump(2) << '\n';
  FV_REQUIRE(out.good(), "error while writing field file '{}'", path);
}

}  // namespace fv::field
