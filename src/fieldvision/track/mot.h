// Track files and their evaluation. TRACKS.csv (CONTRACT.md) is MOTChallenge's first seven
// columns (1-based frames) plus the field position and the frame's time:
// frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s (empty when unknown). MOT17
// ground truth (no header; conf 0 = ignore, then class and visibility) is read too and scored with
// TrackEval's MOT17 rules (EvaluateMot). Metrics the MOTChallenge way: CLEAR MOT (Bernardin &
// Stiefelhagen 2008: MOTA, MOTP as the mean IoU of matches, ID switches; per frame a Hungarian
// matching at IoU >= 0.5 that keeps last frame's pairs when still valid), IDF1 (Ristani et al.
// 2016: a one-to-one matching of whole trajectories that maximises the frames matched) and HOTA
// (Luiten et al. 2021, as TrackEval computes it: alpha from 0.05 to 0.95, DetA x AssA).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace fv::track {

struct TrackRow {
  int frame = 0;
  int id = 0;
  cv::Rect2d box;
  double conf = 1.0;
  std::optional<double> x_m, y_m;
  std::optional<double> time_s;  // the frame's time in the video (seconds)
  // MOT ground truth only (9-column files without header): class (1 pedestrian, 2 person on
  // vehicle, 7 static person, 8 distractor, 12 reflection, ...) and visibility; -1 unknown.
  int mot_class = -1;
  double visibility = -1;
};

// A row's box in its own frame's pixels, for the checks at the image's edges (a tracklet ending at
// the border, a box whose top is the image's): with a moving camera the rows are on its canvas
// (view_canvas.h). Empty: the box as it is.
using FrameBoxOf = std::function<cv::Rect2d(const TrackRow&)>;

// The largest pixel coordinate and size of a box TRACKS.csv holds (ReadTracksCsv refuses others).
inline constexpr double kMaxBoxPixel = 1e6;
// Whether a box is finite, of non-negative size and within kMaxBoxPixel.
bool BoxInRange(const cv::Rect2d& box);

// Writes TRACKS.csv with the contract header (rows in the order given), through a temporary file
// renamed at the end (a failed write leaves an existing file as it was).
void WriteTracksCsv(const std::vector<TrackRow>& rows, const std::string& path);
// Writes a MOTChallenge results file (no header, frame,id,bb_left,bb_top,bb_width,bb_height,conf,
// -1,-1,-1) that TrackEval and py-motmetrics read unchanged.
void WriteMotChallenge(const std::vector<TrackRow>& rows, const std::string& path);
// Reads TRACKS.csv (columns found by their header names; files without time_s are accepted), or a
// MOTChallenge file without header (frame,id,left,top,w,h,conf then, with 9 columns, MOT17's
// class and visibility; frames kept as they are). Throws fv::Error naming the file and line.
std::vector<TrackRow> ReadTracksCsv(const std::string& path);

struct MotOptions {
  double iou_threshold = 0.5;  // a match needs IoU >= this (MOTChallenge: 0.5)
  // MOT17's rules when the ground truth has classes (TrackEval, MotChallenge2DBox): estimated
  // boxes matched (IoU >= 0.5, Hungarian) to a distractor (person on vehicle, static person,
  // distractor, reflection) are removed, then ground truth with conf 0 or a class other than
  // pedestrian is removed.
  bool mot17_rules = true;
  // Added to every estimated frame number before matching (0: both files number frames alike).
  int frame_offset = 0;
  // Estimated rows in frames outside the ground truth's first..last frame are left out (a
  // ground truth that covers part of a video).
  bool clip_to_gt_frames = true;
  // Ground-truth rows in frames outside the estimate's first..last frame are left out (an
  // estimate of a clip of the video); false: they count as misses.
  bool clip_to_est_frames = false;
  void Check() const;
};

// What EvaluateMot left out before scoring.
struct MotPreprocessing {
  int gt_ignored = 0;          // conf 0 or not a pedestrian (MOT17 rules)
  int est_on_distractors = 0;  // estimated boxes matched to a distractor (MOT17 rules)
  int est_outside_gt_frames = 0;
  int gt_first = 0, gt_last = 0;  // the ground truth's frames when estimates outside were left out
  bool est_clipped = false;
  // Ground-truth boxes in frames outside the estimate's first..last frame (est_first..est_last,
  // after frame_offset): left out with clip_to_est_frames, else counted as misses (Summary notes
  // it when over a tenth of the ground truth's frames lie outside: a clip of the video).
  int gt_outside_est_frames = 0;
  int est_first = 0, est_last = 0;
  int gt_frames = 0, gt_frames_outside_est = 0;  // ground-truth frames with boxes, and outside
  bool gt_clipped = false;
  // The frame offset (added to the estimate) whose matches (IoU >= 0.5) have the largest summed
  // IoU, tried over -2..2, and the sums at offset 0 and at that one: a 0-based file scored
  // against 1-based ground truth shows up as best_offset 1 (Summary warns).
  int best_offset = 0;
  double iou_at_zero = 0, iou_at_best = 0;
  std::string Summary() const;
  // Drops from `gt` the rows left out as outside the estimate's frames (with gt_clipped) and
  // from `est` (its frames as in its file, `frame_offset` not yet added) those left out as outside
  // the ground truth's (est_clipped), so that what else is scored on both (field positions, the
  // coach's numbers) covers the frames the metrics do.
  void ClipAsScored(std::vector<TrackRow>& gt, std::vector<TrackRow>& est, int frame_offset) const;
};

struct MotMetrics {
  int frames = 0;
  int gt_boxes = 0, est_boxes = 0;
  int gt_ids = 0, est_ids = 0;
  int tp = 0, fp = 0, fn = 0, id_switches = 0, fragmentations = 0;
  double mota = 0, motp = 0;  // MOTP: mean IoU of the matches
  double idf1 = 0, idp = 0, idr = 0;
  double hota = 0, deta = 0, assa = 0;
  double precision = 0, recall = 0;
  int mostly_tracked = 0, mostly_lost = 0;  // ground-truth ids covered >= 80 % / <= 20 %
  MotPreprocessing preprocessing;
  std::string Summary() const;
  std::string ToJson() const;
};

MotMetrics EvaluateMot(const std::vector<TrackRow>& gt, const std::vector<TrackRow>& est,
                       const MotOptions& options = {});

}  // namespace fv::track
