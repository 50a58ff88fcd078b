// The players pipeline: frames (read in a separate thread) -> person detector (detection.h) ->
// ByteTrack tracker (bytetrack.h) -> foot points mapped to the ground plane z = 0 through the
// calibration -> TRACKS.csv rows; then short gaps of a track are filled by linear interpolation
// (as ByteTrack does for MOTChallenge results) and, optionally, tracks are split into two teams by
// k-means on their torso colours. Reports the time spent per stage.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"
#include "fieldvision/track/bytetrack.h"
#include "fieldvision/track/detection.h"
#include "fieldvision/track/mot.h"

namespace fv::track {

struct PlayersOptions {
  DetectorOptions detector;
  TrackerOptions tracker;
  // Keep only people whose foot point is inside the field plus this margin (needs `field`).
  double field_margin_m = 3.0;
  int max_frames = 0;            // 0: the whole video
  int interpolate_max_gap = 20;  // fill track gaps up to this many frames (0: off)
  int min_track_frames = 5;      // drop tracks seen in fewer frames (0: keep all)
  bool teams = false;            // assign teams (k-means, k = 2, on torso colour)
  bool progress = true;          // fv::Progress on stderr
  double fps = 0;                // 0: from the video (falls back to 25)
  // Read the detections from this file (MOTChallenge det.txt style, detection.h) instead of
  // running the detector; the video is still read (the tracker's appearance model uses the
  // frames). The same filtering (min height, field area, NMS, score threshold) is applied.
  std::string detections_in;
  // Write the detections of every frame (after filtering) to this file; reading it back with
  // detections_in gives the same tracks.
  std::string detections_out;

  void Check() const;
};

struct StageTimes {
  double read_s = 0, detect_s = 0, track_s = 0, map_s = 0, total_s = 0;
};

struct PlayersResult {
  std::vector<TrackRow> rows;
  std::map<int, int> team_of;  // id -> 0/1 when teams were asked for
  int frames = 0;
  double fps = 0;        // video frame rate used
  int detections = 0;    // after filtering and NMS, all frames
  int tracks = 0;        // ids in the output
  int interpolated = 0;  // rows added by gap filling
  int off_ground = 0;    // rows whose foot point does not meet the ground
  TrackerStats tracker;
  StageTimes times;
  std::string detector;
  std::string Summary() const;
};

// Throws fv::Error when the camera's image size differs from the video's (names both).
void CheckCameraMatchesVideo(const Camera& camera, int width, int height, const std::string& video);

// Runs the pipeline on a video (any file OpenCV reads or an image pattern). `camera` may be
// uncalibrated (no pose): then no field positions. `field` (optional) limits detections.
PlayersResult RunPlayers(const std::string& video, const Camera* camera, const FieldModel* field,
                         const PlayersOptions& options);

// Linear interpolation of gaps (<= max_gap frames) inside each track; returns the rows added.
int InterpolateGaps(std::vector<TrackRow>& rows, int max_gap, const Camera* camera,
                    double foot_offset_m = 0.0);

}  // namespace fv::track
