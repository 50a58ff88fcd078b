// The players pipeline: frames (read in a separate thread) -> person detector (detection.h) ->
// ByteTrack tracker (bytetrack.h) -> foot points mapped to the ground plane z = 0 through the
// calibration -> TRACKS.csv rows; then, offline, tracklets of one person broken by an occlusion are
// joined (StitchTracklets: motion across the gap and torso colour), short gaps of a track are
// filled by linear interpolation (as ByteTrack does for MOTChallenge results) and, optionally,
// tracks are split into two teams by k-means on their torso colours. Reports the time spent per
// stage.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"
#include "fieldvision/track/bytetrack.h"
#include "fieldvision/track/camera_motion.h"
#include "fieldvision/track/detection.h"
#include "fieldvision/track/ground_smoother.h"
#include "fieldvision/track/hidden_feet.h"
#include "fieldvision/track/line_anchor.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/track/view_canvas.h"
#include "fieldvision/track/view_drift.h"

namespace fv::track {

// The offline pass that joins tracklets of one person after the tracker: a tracklet A that ends
// and a tracklet B that starts at most max_gap_s later are joined (B takes A's id) when B's start
// is where A's motion leads across the gap (A extrapolated forward and B backward by half the gap
// each, at their end/start velocities, meet within reach_m + speed_slack_mps * gap) and their
// mean torso colours are alike (Bhattacharyya distance <= max_appearance_distance). Pairs are
// joined greedily by increasing cost (sum of both distances relative to their limits), each
// tracklet once on each side. A tracklet that ends at the image border and one that starts at the
// border are not joined (the person left and someone came in; MOTChallenge gives a new id).
// Positions are on the field when known, else in pixels scaled to metres by the box height
// (person_height_m).
struct StitchOptions {
  double max_gap_s = 4.0;          // longest gap between tracklets joined (0: off)
  double reach_m = 1.0;            // distance accepted at a gap of 0 (position noise)
  double speed_slack_mps = 1.0;    // plus this much per second of gap (velocity error)
  double max_speed_mps = 3.0;      // end/start velocities are clamped to this speed
  double velocity_window_s = 1.0;  // velocity from the tracklet's last/first this many seconds
  double max_appearance_distance = 0.3;  // torso histograms (0: same, 1: disjoint)
  // Near its ends, a box shorter than this share of the person's height there (the median box
  // height within height_window_s of the end) is taken as partly hidden, its legs behind someone
  // nearer the camera: its foot point is taken below the box's top at that height (with a posed
  // camera, or in pixels without field positions), else the box is not used for the end
  // positions and velocities.
  double full_height_ratio = 0.85;
  double height_window_s = 3.0;
  double border_px = 8;           // closer than this to the image edge counts as at the border
  double person_height_m = 1.75;  // pixels -> metres without a calibrated camera

  void Check() const;
};

// Mean appearance of one track: the sum of its torso histograms (TorsoHistogram) and how many.
struct TrackAppearance {
  cv::Mat sum;
  int count = 0;
};

struct PlayersOptions {
  DetectorOptions detector;
  TrackerOptions tracker;
  // Keep only people whose foot point is inside the field plus this margin (needs `field`).
  double field_margin_m = 3.0;
  int max_frames = 0;            // 0: the whole video
  int interpolate_max_gap = 20;  // fill track gaps up to this many frames (0: off)
  // Drop tracks seen in fewer frames (mostly false detections; 0: keep all). On a clip shorter
  // than twice this, the minimum is half the clip's frames (a 3-frame clip keeps 2-frame tracks).
  // The summary says how many were dropped.
  int min_track_frames = 5;
  StitchOptions stitch;           // offline joining of tracklets (before gap interpolation)
  HiddenFeetOptions hidden_feet;  // feet of partly hidden people (calibrated camera)
  GroundSmoothOptions smooth;     // offline smoothing of field positions (calibrated camera)
  bool teams = false;             // assign teams (k-means, k = 2, on torso colour)
  bool progress = true;           // fv::util::Progress on stderr
  // Overrides the video's time: frame i (0-based) is at i / fps seconds. 0: the video's
  // timestamps, else its frame rate (TimesOfFrames).
  double fps = 0;
  // Read the detections from this file (MOTChallenge det.txt style, detection.h) instead of
  // running the detector; the video is still read (the tracker's appearance model uses the
  // frames). The same filtering (min height, field area, NMS, score threshold) is applied.
  std::string detections_in;
  // Write the detections of every frame (after filtering; with a moving camera before the field
  // filter, which is applied on its canvas) to this file; reading it back with
  // detections_in and the same options gives the same tracks.
  std::string detections_out;
  // A camera that sways, turns, pans or drifts (camera_motion.h): every frame is registered to
  // the first, the view the camera file's pose holds for, and tracked on that view widened by
  // camera_motion.canvas_margin (view_canvas.h); the rows' boxes are given back in each frame's
  // own pixels. Not with the "motion" detector
  // (background subtraction needs a still camera).
  bool moving_camera = false;
  CameraMotionOptions camera_motion;
  // With a moving camera, a posed camera file and a field with painted lines: each keyframe's
  // view is held to the lines it sees (line_anchor.h), which stops the registration's drift.
  bool hold_to_lines = true;
  LineAnchorOptions line_anchor;
  // A moving camera that moves as well as turns (a drone, a camera carried along the side line):
  // its frames are registered on the ground alone (one homography maps frame to frame there, not
  // over the stands) and the lines refit each frame's whole pose (line_anchor.refine.fix_centre
  // false). Needs a posed camera and a field.
  bool moving_centre = false;
  // Without moving_camera: the view is checked for moves (view_drift.h), which the still run's
  // positions do not follow (PlayersResult::view_drift).
  ViewDriftOptions view_drift;

  void Check() const;
};

// The time of each frame of a video (CONTRACT.md: from the video, never assumed).
struct FrameTimes {
  std::vector<double> time_s;  // per frame (0-based); empty when the video gives no time
  double fps = 0;              // the rate used (median of the timestamps' steps); 0: none
  std::string source;          // where the time came from, for messages
};

// Frame times from, in order: `fps_override` (> 0: frame i at i / fps), the container's
// timestamps (CAP_PROP_POS_MSEC per frame, used when finite and strictly increasing), the
// container's frame rate; else none.
FrameTimes TimesOfFrames(const std::vector<double>& container_ms, double container_fps,
                         double fps_override);

struct StageTimes {
  double read_s = 0, detect_s = 0, track_s = 0, map_s = 0, total_s = 0;
  double register_s = 0;  // a moving camera's frames registered to the first (a still one's
                          // checked: view_drift.h)
};

struct PlayersResult {
  std::vector<TrackRow> rows;
  std::map<int, int> team_of;  // id -> 0/1 when teams were asked for
  int frames = 0;
  double fps = 0;            // frame rate used by the tracker (25 when the video gives none)
  FrameTimes time;           // the rows' time_s (TrackRow::time_s) and where it came from
  int min_track_frames = 0;  // the minimum track length applied (PlayersOptions)
  int dropped_tracks = 0;    // tracks shorter than that, dropped
  int detections = 0;        // after filtering and NMS, all frames
  int tracks = 0;            // ids in the output
  int interpolated = 0;      // rows added by gap filling
  int mended_feet = 0;       // rows of partly hidden people whose foot was moved (hidden_feet.h)
  int stitched = 0;          // tracklets joined to an earlier one
  std::string frames_note;   // what the frame source did to the frames (FramesNote), or ""
  int off_ground = 0;        // rows whose foot point does not meet the ground
  int outside_frames = 0;    // a moving camera's rows whose box their frame cannot show (left out)
  // A moving camera's detections whose foot point fell beyond its canvas (left out), in how many
  // frames, and the first such frame (1-based; 0: none).
  int beyond_canvas = 0;
  int beyond_canvas_frames = 0;
  int first_beyond_canvas = 0;
  GroundSmoothResult smoothing;
  std::optional<CameraMotionStats> camera_motion;  // with PlayersOptions::moving_camera
  std::optional<LineAnchorStats> line_anchor;      // with PlayersOptions::hold_to_lines in use
  std::optional<ViewDriftStats> view_drift;        // without PlayersOptions::moving_camera
  // The canvas its frames were tracked on (view_canvas.h), as TrackOverlay::SetCameraMotion
  // takes it.
  std::optional<ViewCanvas> canvas;
  TrackerStats tracker;
  StageTimes times;
  std::string detector;
  std::string Summary() const;
};

// Runs the pipeline on a video (any file OpenCV reads or an image pattern). `camera` may be
// null or uncalibrated (no pose): then boxes only, no field positions. `field` (optional) limits
// detections. Rows number frames from 1 and carry the frame's time (TimesOfFrames; an image
// sequence has a time only with options.fps).
PlayersResult RunPlayers(const std::string& video, const camera::Camera* camera,
                         const field::FieldModel* field, const PlayersOptions& options);

// The camera that mapped the rows' foot points to the field (null or without a pose: none), for
// the feet of partly hidden people (StitchOptions::full_height_ratio).
struct StitchCamera {
  const camera::Camera* camera = nullptr;
  double foot_offset_m = 0.0;  // as TrackerOptions::foot_offset_m
  FrameBoxOf frame_box;        // rows on a moving camera's canvas: each one's box in its frame
  cv::Size canvas_size;        // the canvas's size (with frame_box)
};

// Joins tracklets in `rows` (StitchOptions); `appearance` by id (ids without one are joined on
// motion alone only if options.max_appearance_distance >= 1); `image` is the frame size (for the
// border rule; empty: no border rule). Returns the number of joins.
int StitchTracklets(std::vector<TrackRow>& rows, const std::map<int, TrackAppearance>& appearance,
                    const StitchOptions& options, double fps, cv::Size image,
                    const StitchCamera& camera = {});

// Linear interpolation of gaps (<= max_gap frames) inside each track; returns the rows added.
int InterpolateGaps(std::vector<TrackRow>& rows, int max_gap, const camera::Camera* camera,
                    double foot_offset_m = 0.0);

}  // namespace fv::track
