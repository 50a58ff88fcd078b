// The fusion node (`fieldvision fuse`): receives camera nodes' detections (messages.h) on a ZeroMQ
// ROUTER socket, answers clock pings (clock_sync.h), pairs frames by capture time
// (pipeline/live_sync.h), triangulates them (pipeline/fusion_stage.h), writes BALL.csv and
// publishes positions and closed flights; bad messages and unknown cameras are counted and dropped.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fieldvision/net/messages.h"
#include "fieldvision/pipeline/fusion_stage.h"
#include "fieldvision/pipeline/job.h"
#include "fieldvision/pipeline/live_flights.h"
#include "fieldvision/pipeline/live_sync.h"

namespace fv::net {

struct FuseOptions {
  std::string listen;  // tcp://HOST:PORT (127.0.0.1 unless told otherwise; PORT * : any free)
  std::vector<std::string> cameras;  // camera files; nodes are matched by camera name
  std::string out;                   // BALL.csv
  std::string publish;               // optional PUB endpoint for positions, tcp://HOST:PORT
  double idle_exit_s =
      0;  // exit after this many seconds without messages (after the first); 0: never
  double ball_diameter_m = 0.22;
  pipeline::LiveSyncOptions sync;
  // Nodes reading files as fast as they can (frames on the media clock): a camera is waited for
  // this long instead of sync.max_wait_s, as a slower node's frames are not late, only slower
  // (one that starts later, builds its background first or decodes more); live cameras keep
  // sync.max_wait_s. The larger of the two is used. At most 9 s: a node in step with the hints
  // goes on without them after 10 s (node.h).
  double media_max_wait_s = 5.0;
  // Flights as they close (a worker thread analyses the positions; published on topic
  // "flight"); analysis.ball_radius_m is set from ball_diameter_m.
  bool flights = true;
  pipeline::LiveFlightsOptions flight_options;
  recon::TriangulationOptions triangulation;
  // Each fused position off the ground goes back to every node as a hint (messages.h), where the
  // camera stage looks for the ball (pipeline/ball_hints.h).
  bool hints = true;
  bool progress = true;
  pipeline::JobControl* control =
      nullptr;  // optional: progress callback and stop check (e.g. Ctrl-C)
  // Optional: called once listening, with the address bound (the port chosen for PORT *).
  std::function<void(const std::string& endpoint)> on_listening;
  void Check() const;  // throws fv::Error naming the bad option
};

struct FuseCameraReport {
  std::string name;
  long long frames = 0;  // frame messages received
  long long sessions = 0;
  // Messages ignored: from a second node sending as this camera while the first went on, or
  // from a node whose images are not the size of this camera file's.
  long long refused = 0;
  bool has_offset = false;
  double offset_s = 0;  // the node's last clock estimate (fuse - node)
};

struct FuseSummary {
  std::vector<FuseCameraReport> cameras;
  long long messages = 0;
  long long malformed = 0, oversized = 0, wrong_version = 0;
  long long unknown_camera = 0;  // messages naming no camera of the rig
  long long unsynced = 0;        // live frames sent before the node had a clock estimate
  long long clock_mismatch = 0;  // media-time frames among system-clock ones or vice versa
  std::vector<pipeline::LiveCameraStats> sync;
  std::vector<std::string> sync_problems;
  long long groups = 0;
  long long paired_groups = 0;  // of those, frames that two or more cameras delivered
  pipeline::FusionStats fusion;
  long long rows_written = 0;
  bool written = false;  // --out was written: false when no frame arrived (it is left as it was)
  long long published = 0;
  long long hints_sent = 0;            // hint messages handed to the nodes' sockets
  std::vector<recon::Flight> flights;  // closed flights, in the order published
  long long flights_published = 0;
  std::vector<double> latency_s;  // capture -> fused, per frame fused (system clocks only)
  // Where the latency of each of those frames went (the slowest camera of the frame; < 0: the
  // nodes did not say): capture -> the node had the frame, the node's work, capture -> the last
  // message here, and the rest (waiting for pairing, triangulation).
  struct LatencyParts {
    double queued_s = -1, process_s = -1, arrival_s = 0, pairing_s = 0;
  };
  std::vector<LatencyParts> latency_parts;
  double seconds = 0;
  std::string ToString() const;
};

FuseSummary RunFuse(const FuseOptions& options);

// The camera and session a node's message names; nullopt for a pong, ball, flight or hint message
// (sent by fuse, never to it).
std::optional<std::pair<std::string, std::string>> SenderOf(const Message& m);

}  // namespace fv::net
