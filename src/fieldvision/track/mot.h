// Track files and their evaluation. TRACKS.csv (CONTRACT.md) is MOTChallenge's first seven
// columns plus the field position: frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m
// (x_m, y_m empty when unknown). Metrics the MOTChallenge way: CLEAR MOT (Bernardin & Stiefelhagen
// 2008: MOTA, MOTP as the mean IoU of matches, ID switches; per frame a Hungarian matching at
// IoU >= 0.5 that keeps last frame's pairs when still valid), IDF1 (Ristani et al. 2016: a
// one-to-one matching of whole trajectories that maximises the frames matched) and HOTA (Luiten
// et al. 2021, as TrackEval computes it: alpha from 0.05 to 0.95, DetA x AssA).
#pragma once

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
};

// Writes TRACKS.csv with the contract header (rows in the order given).
void WriteTracksCsv(const std::vector<TrackRow>& rows, const std::string& path);
// Reads TRACKS.csv, or a MOTChallenge file without header (frame,id,left,top,w,h,conf,...,
// 1-based frames are kept as they are). Throws fv::Error naming the file and line.
std::vector<TrackRow> ReadTracksCsv(const std::string& path);

struct MotOptions {
  double iou_threshold = 0.5;  // a match needs IoU >= this (MOTChallenge: 0.5)
  void Check() const;
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
  std::string Summary() const;
  std::string ToJson() const;
};

MotMetrics EvaluateMot(const std::vector<TrackRow>& gt, const std::vector<TrackRow>& est,
                       const MotOptions& options = {});

}  // namespace fv::track
