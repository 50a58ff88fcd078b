#include "fieldvision/net/messages.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "fieldvision/pipeline/camera_message.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"

namespace fv::net {
namespace {

using nlohmann::json;

// The message's fields through util's strict readers: "message: missing key 'k'", "message: key
// 'k' must be a number" (or is not finite, must be an integer, must be a string).
constexpr const char* kCtx = "message";

double Num(const json& j, const char* key) { return util::JsonNumber(j, key, kCtx); }

long long Int(const json& j, const char* key) { return util::JsonInt64(j, key, kCtx); }

std::string Str(const json& j, const char* key, size_t max_len = 256) {
  std::string s = util::JsonString(j, key, kCtx);
  FV_REQUIRE(s.size() <= max_len, "message: key '{}' longer than {} characters", key, max_len);
  return s;
}

std::string Clock(const json& j) {
  std::string c = Str(j, "clock");
  FV_REQUIRE(c == "system" || c == "media", "message: 'clock' must be system or media");
  return c;
}

struct Encoder {
  json operator()(const HelloMessage& m) const {
    return {{"type", "hello"},    {"camera", m.camera}, {"session", m.session}, {"width", m.width},
            {"height", m.height}, {"fps", m.fps},       {"source", m.source},   {"clock", m.clock}};
  }
  json operator()(const FrameMessage& m) const {
    json j = {{"type", "frame"},      {"camera", m.camera},
              {"session", m.session}, {"frame", m.frame},
              {"time_s", m.time_s},   {"origin", m.origin},
              {"clock", m.clock},     {"candidates", pipeline::CandidatesToJson(m.candidates)}};
    if (m.has_offset) j["offset_s"] = m.offset_s;
    if (m.queued_s >= 0) j["queued_s"] = m.queued_s;
    if (m.process_s >= 0) j["process_s"] = m.process_s;
    return j;
  }
  json operator()(const SkipMessage& m) const {
    json j = {{"type", "skip"},      {"camera", m.camera}, {"session", m.session},
              {"frame", m.frame},    {"time_s", m.time_s}, {"clock", m.clock},
              {"skipped", m.skipped}};
    if (m.has_offset) j["offset_s"] = m.offset_s;
    return j;
  }
  json operator()(const PingMessage& m) const {
    return {{"type", "ping"}, {"camera", m.camera}, {"session", m.session}, {"t0_s", m.t0_s}};
  }
  json operator()(const PongMessage& m) const {
    json j = {
        {"type", "pong"}, {"t0_s", m.t0_s}, {"t1_s", m.t1_s}, {"t2_s", m.t2_s}, {"hints", m.hints}};
    if (!m.refused.empty()) {
      j["refused"] = m.refused;
      j["refused_for_now"] = m.refused_for_now;
    }
    return j;
  }
  json operator()(const ByeMessage& m) const {
    return {{"type", "bye"}, {"camera", m.camera}, {"session", m.session}, {"frames", m.frames}};
  }
  json operator()(const BallMessage& m) const {
    return {{"type", "ball"},     {"frame", m.frame},   {"time_s", m.time_s},
            {"x_m", m.x_m},       {"y_m", m.y_m},       {"z_m", m.z_m},
            {"n_cams", m.n_cams}, {"err_px", m.err_px}, {"latency_s", m.latency_s}};
  }
  json operator()(const HintMessage& m) const {
    if (m.lost) return {{"type", "hint"}, {"time_s", m.time_s}, {"lost", true}};
    return {{"type", "hint"}, {"time_s", m.time_s}, {"x_m", m.x_m},
            {"y_m", m.y_m},   {"z_m", m.z_m},       {"radius_m", m.radius_m}};
  }
  json operator()(const FlightMessage& m) const {
    return {{"type", "flight"},
            {"index", m.index},
            {"start", m.start},
            {"end", m.end},
            {"t_start_s", m.t_start_s},
            {"t_end_s", m.t_end_s},
            {"origin_m", util::JsonFromVector(Eigen::Vector3d(m.origin_m))},
            {"landing_m", util::JsonFromVector(Eigen::Vector3d(m.landing_m))},
            {"t_landing_s", m.t_landing_s},
            {"landing_extrapolated", m.landing_extrapolated},
            {"apex_m", util::JsonFromVector(Eigen::Vector3d(m.apex_m))},
            {"v0_mps", util::JsonFromVector(Eigen::Vector3d(m.v0_mps))},
            {"speed_mps", m.speed_mps},
            {"rmse_m", m.rmse_m},
            {"model", m.model},
            {"samples", m.samples}};
  }
};

void Vec3(const json& j, const char* key, double* out) {
  Eigen::Vector3d::Map(out) = util::JsonVector<3>(j, key, kCtx);
}

}  // namespace

std::string Encode(const Message& message) {
  json j = std::visit(Encoder{}, message);
  j["v"] = kSchemaVersion;
  return j.dump();
}

namespace {

// The camera, session, frame and time of a frame or skip message, in that order.
template <typename M>
void ReadFrameStamp(const json& j, M& m) {
  m.camera = Str(j, "camera");
  m.session = Str(j, "session");
  m.frame = Int(j, "frame");
  FV_REQUIRE(m.frame >= 0, "message: 'frame' must be >= 0");
  m.time_s = Num(j, "time_s");
}

// The optional clock offset of a frame or skip message.
template <typename M>
void ReadOffset(const json& j, M& m) {
  if (!j.contains("offset_s")) return;
  m.offset_s = Num(j, "offset_s");
  m.has_offset = true;
}

Message DecodeChecked(const void* data, size_t size) {
  const char* p = static_cast<const char*>(data);
  json j = json::parse(p, p + size, nullptr, /*allow_exceptions=*/false);
  FV_REQUIRE(!j.is_discarded() && j.is_object(), "message: not a JSON object");
  FV_REQUIRE(j.contains("v") && j["v"].is_number_integer(), "message: no schema version 'v'");
  const long long v = j["v"].get<long long>();
  if (v != kSchemaVersion) {
    throw MessageError(
        MessageError::Reason::kVersion,
        fmt::format("message: schema version {} (this program speaks {})", v, kSchemaVersion));
  }
  const std::string type = Str(j, "type");
  if (type == "frame") {
    FrameMessage m;
    ReadFrameStamp(j, m);
    m.origin = Str(j, "origin");
    m.clock = Clock(j);
    ReadOffset(j, m);
    for (auto [key, value] : {std::pair{"queued_s", &m.queued_s}, {"process_s", &m.process_s}}) {
      if (!j.contains(key)) continue;
      *value = Num(j, key);
      FV_REQUIRE(*value >= 0 && *value < 3600, "message: '{}' must be in [0, 3600) s", key);
    }
    FV_REQUIRE(j.contains("candidates"), "message: 'candidates' missing");
    FV_REQUIRE(j["candidates"].size() <= 1000, "message: more than 1000 candidates");
    m.candidates = pipeline::CandidatesFromJson(j["candidates"], "message");
    return m;
  }
  if (type == "skip") {
    SkipMessage m;
    ReadFrameStamp(j, m);
    m.clock = Clock(j);
    m.skipped = Int(j, "skipped");
    FV_REQUIRE(m.skipped >= 0, "message: 'skipped' must be >= 0");
    ReadOffset(j, m);
    return m;
  }
  if (type == "ping") {
    return PingMessage{Str(j, "camera"), Str(j, "session"), Num(j, "t0_s")};
  }
  if (type == "pong") {
    PongMessage m;
    m.t0_s = Num(j, "t0_s");
    m.t1_s = Num(j, "t1_s");
    m.t2_s = Num(j, "t2_s");
    if (j.contains("hints")) {
      FV_REQUIRE(j["hints"].is_boolean(), "message: 'hints' must be true or false");
      m.hints = j["hints"].get<bool>();
    }
    if (j.contains("refused")) {
      m.refused = Str(j, "refused", 1000);
      FV_REQUIRE(!m.refused.empty(), "message: 'refused' must say why");
      m.refused_for_now = j.value("refused_for_now", false);
    }
    return m;
  }
  if (type == "hello") {
    HelloMessage m;
    m.camera = Str(j, "camera");
    m.session = Str(j, "session");
    m.width = util::JsonInt(j, "width", kCtx);
    m.height = util::JsonInt(j, "height", kCtx);
    m.fps = Num(j, "fps");
    m.source = Str(j, "source", 4096);
    m.clock = Clock(j);
    return m;
  }
  if (type == "bye") return ByeMessage{Str(j, "camera"), Str(j, "session"), Int(j, "frames")};
  if (type == "ball") {
    BallMessage m;
    m.frame = Int(j, "frame");
    m.time_s = Num(j, "time_s");
    m.x_m = Num(j, "x_m");
    m.y_m = Num(j, "y_m");
    m.z_m = Num(j, "z_m");
    m.n_cams = util::JsonInt(j, "n_cams", kCtx);
    m.err_px = Num(j, "err_px");
    m.latency_s = Num(j, "latency_s");
    return m;
  }
  if (type == "hint") {
    HintMessage m;
    m.time_s = Num(j, "time_s");
    if (j.contains("lost")) {
      FV_REQUIRE(j["lost"].is_boolean() && j["lost"].get<bool>(), "message: 'lost' must be true");
      m.lost = true;
      return m;
    }
    m.x_m = Num(j, "x_m");
    m.y_m = Num(j, "y_m");
    m.z_m = Num(j, "z_m");
    m.radius_m = Num(j, "radius_m");
    FV_REQUIRE(m.radius_m > 0 && m.radius_m < 1, "message: 'radius_m' must be in (0, 1) m");
    return m;
  }
  if (type == "flight") {
    FlightMessage m;
    m.index = Int(j, "index");
    m.start = Str(j, "start");
    m.end = Str(j, "end");
    m.t_start_s = Num(j, "t_start_s");
    m.t_end_s = Num(j, "t_end_s");
    Vec3(j, "origin_m", m.origin_m);
    Vec3(j, "landing_m", m.landing_m);
    m.t_landing_s = Num(j, "t_landing_s");
    m.landing_extrapolated = util::JsonBool(j, "landing_extrapolated", kCtx);
    Vec3(j, "apex_m", m.apex_m);
    Vec3(j, "v0_mps", m.v0_mps);
    m.speed_mps = Num(j, "speed_mps");
    m.rmse_m = Num(j, "rmse_m");
    m.model = Str(j, "model");
    m.samples = Int(j, "samples");
    return m;
  }
  Throw("message: unknown type '{}'", type);
}

}  // namespace

Message Decode(const void* data, size_t size) {
  if (size > kMaxMessageBytes) {
    throw MessageError(
        MessageError::Reason::kOversized,
        fmt::format("message: {} bytes, more than the limit {}", size, kMaxMessageBytes));
  }
  try {
    return DecodeChecked(data, size);
  } catch (const MessageError&) {
    throw;
  } catch (const std::exception& e) {  // fv::Error, or nlohmann's for a bad value type
    throw MessageError(MessageError::Reason::kMalformed, e.what());
  }
}

}  // namespace fv::net
