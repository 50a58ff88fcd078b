// Synchronisation of N camera streams: groups the camera stages' messages into multi-camera
// frames, by frame index (default) or by capture time within a tolerance. Streams may start,
// end, drop or duplicate frames independently: each group holds at most one message per camera,
// a message is never paired with another camera's message from a different frame (index mode)
// or from a moment further away than the tolerance (time mode), and every anomaly is counted
// per camera (gaps, duplicates, out-of-order, unpaired) for the report. Messages of one camera
// must arrive in order. A single-threaded state machine: the fusion stage feeds it.
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "fieldvision/pipeline/camera_message.h"

namespace fv::pipeline {

enum class SyncMode { kFrameIndex, kTimestamp };

struct SyncOptions {
  SyncMode mode = SyncMode::kFrameIndex;
  // Time mode: messages within this many seconds of the group's earliest one are combined;
  // default half a frame at 60 fps. Must be below half the frame interval to be unambiguous.
  double tolerance_s = 0.008;
  void Check() const;  // throws fv::Error naming the bad field
};

// One multi-camera frame: per camera the message, or nothing.
struct SyncedFrame {
  long long frame = 0;  // index mode: the frame; time mode: the lowest-numbered camera's frame
  double time_s = 0.0;  // mean capture time of the messages
  std::vector<std::optional<CameraMessage>> cameras;
  int present() const;
  // Sets frame (the first present camera's) and time_s (the mean of the present cameras') from
  // the messages; returns how many are present.
  int SetFrameAndTime();
};

struct CameraSyncStats {
  long long received = 0;      // messages accepted
  long long gaps = 0;          // frames missing between consecutive messages (drops)
  long long duplicates = 0;    // same frame (or time) again: discarded
  long long out_of_order = 0;  // earlier than the previous message: discarded
  long long unpaired = 0;      // in a group without any other camera
  long long first_frame = -1, last_frame = -1;
  bool ended = false;
};

// One camera's line of a synchronisation report: "<name>: part, part" (the name from `names`,
// "camera <index>" without one); "" when there are no parts.
std::string SyncProblemLine(const std::vector<std::string>& names, size_t camera,
                            const std::vector<std::string>& parts);

struct SyncReport {
  std::vector<CameraSyncStats> cameras;
  long long groups = 0;           // frames emitted
  long long complete_groups = 0;  // with every camera present
  // Frames missing between messages are drops (videos, cameras); in detection files a frame
  // without a row had no detection.
  bool gaps_are_drops = true;
  // One line per camera with a problem (empty when everything paired cleanly), each starting
  // with the camera's name from `names` ("camera <index>" without one, as unnamed cameras are
  // called in the pipelines' summaries).
  std::vector<std::string> Problems(const std::vector<std::string>& names = {}) const;
};

class FrameSynchronizer {
 public:
  FrameSynchronizer(int num_cameras, const SyncOptions& options);
  // Adds a message (camera index must be in range; throws fv::Error otherwise).
  void Add(CameraMessage message);
  // The camera's stream has ended.
  void EndOfStream(int camera);
  // The next frame when it can be decided from what has arrived, else nullopt.
  std::optional<SyncedFrame> Next();
  // A live camera whose next message is needed before Next() can decide; -1 when none.
  int Waiting() const;
  // Every stream ended and every message emitted.
  bool Done() const;
  const SyncReport& report() const { return report_; }

 private:
  int num_cameras_;
  SyncOptions options_;
  std::vector<std::deque<CameraMessage>> buffers_;
  std::vector<long long> last_frame_;
  std::vector<double> last_time_;
  SyncReport report_;
};

}  // namespace fv::pipeline
