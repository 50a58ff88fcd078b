// The messages between camera nodes and the fusion node, and the fusion node's published ball
// positions and flights: JSON objects, one per ZeroMQ message, with the schema version "v" and a
// "type".
//
// node -> fuse (DEALER -> ROUTER):
//   {"v":1,"type":"hello","camera":"cam1","session":"5f..","width":1280,"height":960,"fps":60,
//    "source":"v4l2:/dev/video0","clock":"system"}
//   {"v":1,"type":"frame","camera":"cam1","session":"5f..","frame":12,"time_s":1764612345.2,
//    "origin":"device","clock":"system","offset_s":0.0123,"candidates":[{"u":..,"v":..,"r":..,
//    "sigma":..,"score":..[,"weak":true]}],"queued_s":0.001,"process_s":0.004}
//    (queued_s, process_s optional: capture -> the node has the frame, the node's work on it)
//   {"v":1,"type":"skip","camera":"cam1","session":"5f..","frame":15,"time_s":..,"clock":"system",
//    "offset_s":..,"skipped":2}  (the source skipped 2 frames; frame 15 is being worked on)
//   {"v":1,"type":"ping","camera":"cam1","session":"5f..","t0_s":..}
//   {"v":1,"type":"bye","camera":"cam1","session":"5f..","frames":120}
// fuse -> node: {"v":1,"type":"pong","t0_s":..,"t1_s":..,"t2_s":..}
// fuse -> node: {"v":1,"type":"hint","time_s":..,"x_m":..,"y_m":..,"z_m":..,"radius_m":0.11}
//   each fused position off the ground, to every node (pipeline/ball_hints.h: the node looks for
//   the ball where the cameras together saw it); time_s on the fusion node's clock ("system") or
//   the recording's ("media")
// fuse PUB, topic "ball": {"v":1,"type":"ball","frame":12,"time_s":..,"x_m":..,"y_m":..,
//   "z_m":..,"n_cams":3,"err_px":0.41,"latency_s":0.012}
// fuse PUB, topic "flight", each flight once it has closed (the next one has begun, or the track
//   ended): {"v":1,"type":"flight","index":0,"start":"hit","end":"bounce","t_start_s":..,
//   "t_end_s":..,"origin_m":[x,y,z],"landing_m":[x,y,z],"t_landing_s":..,
//   "landing_extrapolated":false,"apex_m":[x,y,z],"v0_mps":[vx,vy,vz],"speed_mps":..,
//   "rmse_m":..,"model":"drag","samples":54}  (times as the ball's time_s; metres, world frame)
// "clock" says what time_s is measured on: "system" (the node's system clock, Unix seconds; the
// fusion node adds offset_s, the node's estimate of fuse clock - node clock) or "media" (a
// file's own time from 0, the same for every camera of a recording).
#pragma once

#include <cstddef>
#include <string>
#include <variant>
#include <vector>

#include "fieldvision/recon/triangulation.h"
#include "fieldvision/util/error.h"

namespace fv::net {

constexpr int kSchemaVersion = 1;
constexpr size_t kMaxMessageBytes = size_t{64} * 1024;  // larger messages are dropped and counted

struct HelloMessage {
  std::string camera, session;
  int width = 0, height = 0;
  double fps = 0;
  std::string source;
  std::string clock = "system";
};

struct FrameMessage {
  std::string camera, session;
  long long frame = 0;
  double time_s = 0;
  std::string origin;  // TimeOrigin as text
  std::string clock = "system";
  double offset_s = 0;      // fuse clock - node clock (clock "system")
  bool has_offset = false;  // false until the node has a clock estimate
  std::vector<recon::BallObservation> candidates;
  // Optional (< 0: not sent): seconds from capture until the node had the frame (the source's
  // buffer) and the node's work on it (decoding and detection); the fusion node reports them.
  double queued_s = -1, process_s = -1;
};

// Sent when the node's source skipped frames (the node was slower than the camera), before it
// works on the frame that follows them: nothing captured before time_s will come from this
// camera, so the fusion node need not wait for it for those frames.
struct SkipMessage {
  std::string camera, session;
  long long frame = 0;  // the frame the node works on now
  double time_s = 0;    // its capture time, on the clock named by `clock`
  std::string clock = "system";
  double offset_s = 0;
  bool has_offset = false;
  long long skipped = 0;  // frames skipped just before it
};

struct PingMessage {
  std::string camera, session;
  double t0_s = 0;  // node clock when sent
};

struct PongMessage {
  double t0_s = 0, t1_s = 0, t2_s = 0;  // the ping's t0; fuse clock at receipt and at reply
  // The fusion node sends a hint for every frame it decides (optional field; absent: false).
  bool hints = false;
  // Why the fusion node ignores the pinging node's messages (optional; absent: accepted), and
  // whether only for now (another node sends as its camera and has not yet been quiet 1.5 s).
  std::string refused;
  bool refused_for_now = false;
};

struct ByeMessage {
  std::string camera, session;
  long long frames = 0;
};

struct BallMessage {
  long long frame = 0;
  double time_s = 0;
  double x_m = 0, y_m = 0, z_m = 0;
  int n_cams = 0;
  double err_px = 0;
  double latency_s = 0;  // fuse clock at publication - capture time (system clocks only)
};

// Where the cameras together saw the ball (fuse -> node), or (`lost`) that they had no position
// for the frame at time_s: a node then searches its whole frame now and then
// (pipeline/camera_stage.h, unconfirmed_scan_every) instead of keeping its window on a still
// thing of the ball's colour. A lost hint has no position keys (older nodes count it malformed).
struct HintMessage {
  double time_s = 0;
  double x_m = 0, y_m = 0, z_m = 0;
  double radius_m = 0.11;
  bool lost = false;
};

// A flight (an airborne arc between two contacts) once it has closed (pipeline/live_flights.h).
struct FlightMessage {
  long long index = 0;     // from 0 in this fusion run
  std::string start, end;  // what starts and ends it: bounce, ground, hit, track start, track end
  double t_start_s = 0, t_end_s = 0;
  double origin_m[3] = {0, 0, 0};   // ball centre at t_start_s
  double landing_m[3] = {0, 0, 0};  // where it meets the ground (centre)
  double t_landing_s = 0;
  bool landing_extrapolated = false;  // not seen to land (hit, end of track)
  double apex_m[3] = {0, 0, 0};
  double v0_mps[3] = {0, 0, 0};
  double speed_mps = 0;
  double rmse_m = 0;
  std::string model;  // gravity, drag or spin
  long long samples = 0;
};

using Message = std::variant<HelloMessage, FrameMessage, SkipMessage, PingMessage, PongMessage,
                             ByeMessage, BallMessage, FlightMessage, HintMessage>;

// Why a message was refused (Decode throws MessageError).
class MessageError : public Error {
 public:
  enum class Reason { kOversized, kMalformed, kVersion };
  MessageError(Reason reason, const std::string& what) : Error(what), reason_(reason) {}
  Reason reason() const { return reason_; }

 private:
  Reason reason_;
};

std::string Encode(const Message& message);
// Throws MessageError (one line) for oversized data (kOversized), another schema version
// (kVersion), data that is not a JSON object, an unknown type or a missing or bad field
// (kMalformed).
Message Decode(const void* data, size_t size);

}  // namespace fv::net
