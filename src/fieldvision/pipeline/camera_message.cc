#include "fieldvision/pipeline/camera_message.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "fieldvision/util/error.h"

namespace fv::pipeline {
namespace {

using nlohmann::json;

double Number(const json& j, const char* key, const std::string& context) {
  FV_REQUIRE(j.contains(key) && j.at(key).is_number(), "{}: '{}' missing or not a number", context,
             key);
  const double v = j.at(key).get<double>();
  FV_REQUIRE(std::isfinite(v), "{}: '{}' is not finite", context, key);
  return v;
}

}  // namespace

json CandidatesToJson(const std::vector<recon::BallObservation>& candidates) {
  json c = json::array();
  for (const recon::BallObservation& o : candidates) {
    json cj = {{"u", o.centre_px.x()},
               {"v", o.centre_px.y()},
               {"r", o.radius_px},
               {"sigma", o.sigma_px},
               {"score", o.score}};
    if (o.weak) cj["weak"] = true;                                 // absent means false
    if (o.background_change >= 0) cj["bg"] = o.background_change;  // absent: not compared
    c.push_back(std::move(cj));
  }
  return c;
}

std::vector<recon::BallObservation> CandidatesFromJson(const json& j, const std::string& context) {
  FV_REQUIRE(j.is_array(), "{}: 'candidates' is not an array", context);
  std::vector<recon::BallObservation> out;
  for (size_t i = 0; i < j.size(); ++i) {
    const json& c = j[i];
    const std::string ctx = context + ": candidates[" + std::to_string(i) + "]";
    FV_REQUIRE(c.is_object(), "{} is not an object", ctx);
    recon::BallObservation o;
    o.centre_px = {Number(c, "u", ctx), Number(c, "v", ctx)};
    o.radius_px = Number(c, "r", ctx);
    o.sigma_px = Number(c, "sigma", ctx);
    o.score = Number(c, "score", ctx);
    FV_REQUIRE(o.sigma_px > 0, "{}: 'sigma' must be > 0", ctx);
    if (c.contains("weak")) {
      FV_REQUIRE(c["weak"].is_boolean(), "{}: 'weak' is not true or false", ctx);
      o.weak = c["weak"].get<bool>();
    }
    if (c.contains("bg")) {
      o.background_change = Number(c, "bg", ctx);
      FV_REQUIRE(o.background_change >= 0 && o.background_change <= 1,
                 "{}: 'bg' must be in [0, 1] (got {})", ctx, o.background_change);
    }
    out.push_back(o);
  }
  return out;
}

std::string CameraMessage::ToJsonLine() const {
  json j;
  j["camera"] = camera;
  j["frame"] = frame;
  j["time_s"] = time_s;
  j["candidates"] = CandidatesToJson(candidates);
  return j.dump();
}

CameraMessage CameraMessage::FromJsonLine(const std::string& line, const std::string& context) {
  json j;
  try {
    j = json::parse(line);
  } catch (const json::exception& e) {
    Throw("{}: not JSON ({})", context, e.what());
  }
  FV_REQUIRE(j.is_object(), "{}: not a JSON object", context);
  CameraMessage m;
  FV_REQUIRE(j.contains("camera") && j["camera"].is_number_integer(),
             "{}: 'camera' missing or not an integer", context);
  FV_REQUIRE(j.contains("frame") && j["frame"].is_number_integer(),
             "{}: 'frame' missing or not an integer", context);
  m.camera = j["camera"].get<int>();
  m.frame = j["frame"].get<long long>();
  FV_REQUIRE(m.camera >= 0 && m.frame >= 0, "{}: 'camera' and 'frame' must be >= 0", context);
  m.time_s = Number(j, "time_s", context);
  FV_REQUIRE(j.contains("candidates"), "{}: 'candidates' missing or not an array", context);
  m.candidates = CandidatesFromJson(j["candidates"], context);
  return m;
}

}  // namespace fv::pipeline
