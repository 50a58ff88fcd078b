// Synchronisation of live camera streams by capture time: groups the camera stages' messages
// (times on one common clock) into multi-camera frames, each message with those of the other
// cameras within `tolerance_s` of the group's earliest. A group is decided as soon as every
// active camera has sent something later, or when its first message has waited `max_wait_s`
// (a slow or dead camera never stalls the others: it is left out and its message, if it comes,
// is late). Cameras that sent nothing for max_wait_s are not waited for, nor cameras that said
// they skipped the frames (SkipUntil); a camera not heard from yet is waited for until
// max_wait_s after the first camera was heard (nodes connect one after another). Late, duplicate
// and out-of-order messages are dropped and counted, never paired wrongly; gaps in frame numbers
// count as dropped frames. A restarted camera (a new session) starts a fresh stream. A group's
// frame number is the fastest camera's (NumberInStream), increasing from group to group. A
// single-threaded state machine; the fusion node feeds it. (frame_sync.h is the offline one:
// it waits for every stream, as files never stall.)
#pragma once

#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "fieldvision/pipeline/camera_message.h"
#include "fieldvision/pipeline/frame_sync.h"

namespace fv::pipeline {

struct LiveSyncOptions {
  double tolerance_s = 0.008;  // half a frame at 60 fps
  double max_wait_s = 0.1;     // longest wait for a camera's message of a group
  size_t max_buffered = 1000;  // messages held per camera (the oldest dropped beyond)
  // A message whose time lies further than this from its camera's previous one (or, for its
  // first, from the other cameras' latest) is dropped as implausible: one frame stamped an hour
  // ahead would otherwise decide a group there, after which every camera's frames are late.
  // A camera that goes on in the new time base (three messages in a row, each within this of the
  // one before) is followed there; groups decided past it are forgotten when the other cameras
  // are there too (their clock was stepped back), and its groups wait while a camera it left
  // behind goes on (else they would decide that time for all). 0: off.
  double max_time_jump_s = 10.0;
  void Check() const;  // throws fv::Error naming the bad field
};

struct LiveCameraStats {
  long long received = 0;      // messages accepted
  long long paired = 0;        // in a group with another camera
  long long unpaired = 0;      // in a group alone
  long long gaps = 0;          // frame numbers skipped (dropped upstream)
  long long duplicates = 0;    // the same frame again: dropped
  long long out_of_order = 0;  // earlier than the previous message: dropped
  long long late = 0;          // its group was already decided: dropped
  long long overflow = 0;      // dropped because the buffer was full
  long long restarts = 0;      // new sessions after the first
  long long implausible = 0;   // a time far from the camera's stream (max_time_jump_s): dropped
  bool active = false;
};

class LiveSynchronizer {
 public:
  LiveSynchronizer(int num_cameras, const LiveSyncOptions& options);
  // Changes LiveSyncOptions::max_wait_s from now on (> 0; throws otherwise).
  void SetMaxWait(double max_wait_s);
  // Adds camera `m.camera`'s message, which arrived at `arrival_s` (any steady clock in
  // seconds, the same for Next). Returns false when it was dropped (counted).
  bool Add(CameraMessage m, double arrival_s);
  // The camera is connected (e.g. it answered a clock ping at `arrival_s`): wait for its frames.
  void Admit(int camera, double arrival_s);
  // Nothing captured before `time_s` will come from the camera (its source skipped frames): the
  // groups before it do not wait for it.
  void SkipUntil(int camera, double time_s, double arrival_s);
  // The camera's frame rate as its source tells it (a node's hello), until its frames are seen:
  // the groups' frame numbers follow the fastest camera from the first group on.
  void SetFrameRate(int camera, double fps);
  // The camera restarted (a new session): its stream starts afresh.
  void Restart(int camera);
  // The camera's stream ended: it is no longer waited for.
  void EndOfStream(int camera);
  // The next group that can be decided at `now_s`; with `flush`, any group at all.
  std::optional<SyncedFrame> Next(double now_s, bool flush = false);
  bool Empty() const;
  const std::vector<LiveCameraStats>& stats() const { return stats_; }
  long long groups() const { return groups_; }
  long long complete_groups() const { return complete_groups_; }
  // One line per camera with a problem (empty when everything paired cleanly).
  std::vector<std::string> Problems(const std::vector<std::string>& names) const;

 private:
  struct Held {
    CameraMessage message;
    double arrival_s;
  };
  int n_;
  LiveSyncOptions options_;
  std::vector<std::deque<Held>> buffers_;
  std::vector<LiveCameraStats> stats_;
  std::vector<long long> last_frame_;
  std::vector<double> last_time_;
  std::vector<double> last_arrival_;
  std::vector<double> skip_until_s_;  // SkipUntil
  std::vector<int> jump_run_;         // implausible messages in a row (max_time_jump_s)
  std::vector<double> jump_time_s_;   // the time of the last of them
  // Whether camera c's message at time_s is too far from its stream (max_time_jump_s), counting
  // the run of such messages.
  bool Implausible(int c, double time_s);
  void Heard(int camera, double arrival_s);
  // Whether a group waits for camera `camera` (active or never heard from, and not silent for
  // max_wait_s).
  bool WaitFor(int camera, double now_s) const;
  // Whether a group at time_s lies more than max_time_jump_s past the stream of a camera that
  // still delivers frames that count (one taken within max_wait_s).
  bool FarAheadOfALiveCamera(double time_s, double now_s) const;
  double first_arrival_s_ = std::numeric_limits<double>::infinity();  // of any camera
  // A group's frame number: the fastest camera's (its frame, else where its frame count would
  // be at the group's time), never below the last group's + 1; cameras of other rates or
  // started at other times number their frames otherwise (the first present camera's gave 9,
  // 19, 10, 21, ... with a 30 fps camera among 60 fps ones).
  void NumberInStream(SyncedFrame& out);
  std::vector<double> frame_step_s_;          // each camera's time per frame (smoothed)
  std::vector<double> last_frame_arrival_s_;  // of each camera's last frame taken (not late)
  bool numbered_ = false;
  long long last_out_frame_ = 0;
  bool any_group_ = false;
  double decided_until_s_ = 0;  // messages at or before this time are late
  long long groups_ = 0, complete_groups_ = 0;
};

}  // namespace fv::pipeline
