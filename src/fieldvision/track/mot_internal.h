// The stages of EvaluateMot (mot.h), for tests: rows by frame, CLEAR MOT's per-frame matching,
// the identity (IDF1) and HOTA scores.
#pragma once

#include <map>
#include <utility>
#include <vector>

#include "fieldvision/track/mot.h"

namespace fv::track {

struct MotFrame {
  std::vector<const TrackRow*> gt, est;
};

// One-to-one matching of boxes at IoU >= thr maximising the IoU sum (Hungarian): pairs (i, j).
std::vector<std::pair<int, int>> MatchBoxes(const std::vector<const TrackRow*>& a,
                                            const std::vector<const TrackRow*>& b, double thr);

// The rows by frame and every id as a dense index (in order of first appearance).
struct MotIndex {
  std::map<int, MotFrame> frames;
  std::map<int, int> gt_index, est_index;
};
MotIndex IndexMotRows(const std::vector<TrackRow>& gt, const std::vector<TrackRow>& est);

// IoU of every (ground truth, estimate) pair of one frame.
std::vector<std::vector<double>> FrameIou(const MotFrame& frame);

// CLEAR MOT's matching in one frame: last frame's pairs (gt id -> est id) kept while their IoU is
// at least thr, the Hungarian method on the rest. For each ground-truth box the estimate or -1.
std::vector<int> MatchClearMot(const MotFrame& frame, const std::vector<std::vector<double>>& iou,
                               const std::map<int, int>& last_match, double thr);

// What the per-frame pass gathers for IDF1 and HOTA, by dense id index.
struct MotIdCounts {
  std::vector<std::vector<int>> pair_frames;   // frames with IoU >= thr, per (gt, est) id pair
  std::vector<std::vector<double>> potential;  // HOTA's normalised similarity sums
  std::vector<int> gt_count, est_count;        // boxes per id
};

// CLEAR MOT counts (tp, fp, fn, switches, fragmentations, MOTA, MOTP, precision, recall, mostly
// tracked and lost) into m, and the id-pair counts for the scores below.
MotIdCounts CountClearMot(const MotIndex& index, double thr, MotMetrics& m);

// IDF1, IDP and IDR: the one-to-one id pairing that maximises the frames matched.
void ScoreIdentity(const std::vector<std::vector<int>>& pair_frames, MotMetrics& m);

// HOTA, DetA and AssA over alpha = 0.05..0.95 (TrackEval).
void ScoreHota(const MotIndex& index, const MotIdCounts& counts, MotMetrics& m);

}  // namespace fv::track
