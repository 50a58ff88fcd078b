// The camera node (`fieldvision node`): one camera's frames (any frame source, io/frame_source.h)
// through the camera stage (pipeline/camera_stage.h) to the fusion node over ZeroMQ (a DEALER
// socket connecting to the fusion node's ROUTER; it reconnects by itself when the fusion node
// restarts). An I/O thread owns the socket: it forwards the frame messages, sends a clock ping
// every ping_interval_s (a burst at the start) and turns the replies into the clock offset
// (clock_sync.h) that every frame message carries. Frames the socket cannot take at once (the
// fusion node unreachable or slower) are dropped and counted, never queued without bound.
#pragma once

#include <string>

#include "fieldvision/pipeline/camera_stage.h"
#include "fieldvision/pipeline/job.h"

namespace fv::net {

struct NodeOptions {
  std::string camera;     // camera file (its `name`, else its stem, names the camera)
  std::string video;      // a frame source spec (io/frame_source.h)
  std::string connect;    // the fusion node, tcp://HOST:PORT
  bool realtime = false;  // play a file at its frame rate (live sources always are)
  double start_at_s = 0;  // with realtime: Unix time of frame 0 (0: now)
  // Frames per second of the video (0: its own). An image sequence has none of its own: the node
  // refuses it without this rather than assume one.
  double fps = 0.0;
  // Frames a live source holds for a slow node (the oldest dropped): 2 absorbs a single slow
  // frame (a whole-frame search) without skipping one; 1 keeps only the newest (a node that is
  // too slow on average skips to the newest frame instead of working a frame behind). On the
  // 4-node live bench (1280x960, 2 cores) 2 gave p95 14.4-15.6 ms and no frame skipped in 6 runs,
  // 1 gave 14.7-23.6 ms and 0-5 of 768 frames skipped in 8.
  int live_buffer_frames = 2;
  double ball_diameter_m = 0.22;
  std::string colour = "orange";
  std::string field;  // optional: look for the ball only over this field
  pipeline::BallTrackOptions track;
  long long max_frames = 0;  // 0: all
  bool detect = true;        // false: send frames without candidates (a latency baseline)
  // The camera looks for the ball where the fusion node's newest hint (messages.h,
  // pipeline/ball_hints.h) puts it when its own track has lost it or follows something else, as
  // the offline `ball` does.
  bool hints = true;
  // A file read as fast as possible (not realtime, not live): low-contrast candidates are compared
  // with the camera's background (detect/camera_background.h), as the offline `ball` does.
  bool background = true;
  double connect_wait_s = 5;  // wait this long for the fusion node's first clock reply
  double ping_interval_s = 0.5;
  // Added to this node's clock: simulates a machine whose clock is off (tests, benchmarks).
  double clock_offset_s = 0;
  bool progress = true;
  pipeline::JobControl* control = nullptr;  // optional: progress callback and stop check
  void Check() const;                       // throws fv::Error naming the bad option
};

struct NodeSummary {
  std::string camera;
  std::string source_origin;     // where frame times come from (TimeOrigin)
  std::string camera_note;       // the camera fitted to an encoder's cropped padding, or ""
  long long frames = 0;          // frames read and processed
  long long sent = 0;            // frame messages handed to the socket
  long long send_dropped = 0;    // frame messages the socket could not take
  long long source_dropped = 0;  // frames the live source skipped (node too slow)
  int clock_samples = 0;
  bool has_offset = false;
  double offset_s = 0;        // fuse clock - node clock
  double round_trip_s = 0;    // of the sample used
  long long bad_replies = 0;  // replies that were not valid messages
  long long hints = 0;        // hints from the fusion node used
  // A file read as fast as it can be: frames that waited for the fusion node's decision of the
  // frame `lag` before (in step, as `ball`), and whether that held to the end.
  long long in_step_frames = 0;
  bool in_step_to_end = false;
  pipeline::CameraStageStats stage;
  double process_p50_s = 0, process_p95_s = 0, process_max_s = 0;  // work per frame
  double seconds = 0;
  std::string ToString() const;
};

NodeSummary RunNode(const NodeOptions& options);

}  // namespace fv::net
