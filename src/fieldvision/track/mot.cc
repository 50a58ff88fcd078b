#include "fieldvision/track/mot.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "fieldvision/track/detection.h"
#include "fieldvision/track/hungarian.h"
#include "fieldvision/track/mot_internal.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

namespace fv::track {

namespace {

// Coordinates and size finite and within kMaxBoxPixel (a negative size passes: ReadTracksCsv says
// that apart).
bool BoxWithinPixels(const cv::Rect2d& box) {
  return std::abs(box.x) <= kMaxBoxPixel && std::abs(box.y) <= kMaxBoxPixel &&
         box.width <= kMaxBoxPixel && box.height <= kMaxBoxPixel;
}

}  // namespace

bool BoxInRange(const cv::Rect2d& box) {
  return BoxWithinPixels(box) && box.width >= 0 && box.height >= 0;
}

void WriteTracksCsv(const std::vector<TrackRow>& rows, const std::string& path) {
  util::AtomicWrite(path, [&](const std::string& tmp) {
    util::CsvWriter w(tmp,
                      {"frame", "id", "bb_left", "bb_top", "bb_width", "bb_height", "conf", "x_m",
                       "y_m", "time_s"},
                      4);
    for (const auto& r : rows) {
      w << r.frame << r.id << r.box.x << r.box.y << r.box.width << r.box.height << r.conf;
      if (r.x_m && r.y_m) {
        w << *r.x_m << *r.y_m;
      } else {
        w << ""
          << "";
      }
      if (r.time_s) {
        w << *r.time_s;
      } else {
        w << "";
      }
      w.EndRow();
    }
    w.Close();
  });
}

void WriteMotChallenge(const std::vector<TrackRow>& rows, const std::string& path) {
  util::AtomicWrite(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    FV_REQUIRE(out.good(), "cannot write MOTChallenge file '{}'", path);
    for (const auto& r : rows) {
      out << fmt::format("{},{},{:.2f},{:.2f},{:.2f},{:.2f},{:.4f},-1,-1,-1\n", r.frame, r.id,
                         r.box.x, r.box.y, r.box.width, r.box.height, r.conf);
    }
    out.close();
    FV_REQUIRE(!out.fail(), "cannot write MOTChallenge file '{}'", path);
  });
}

namespace {

// The file's text; whether its first line is a header (not a number: a MOTChallenge file has
// none).
std::string ReadTracksText(const std::string& path, bool* has_header) {
  std::string text = util::ReadCsvText(path, "tracks file");
  const std::string_view body = util::WithoutUtf8Bom(text);  // the parser skips the mark too
  const size_t first = body.find_first_not_of(" \t\r\n");
  *has_header = first != std::string_view::npos &&
                !std::isdigit(static_cast<unsigned char>(body[first])) && body[first] != '-';
  return text;
}

// Row `i` of `t` as a TrackRow, its numbers checked (NaN fails them too).
TrackRow TrackRowAt(const util::CsvTable& t, size_t i, bool has_header) {
  constexpr double kMaxFieldM = 1e4;
  constexpr long long kMaxFrame = 100000000;  // 46 days at 25 frames/s; 2e9 is a damaged file
  const std::string where = t.Where(i);
  auto present = [&](const char* column) { return t.Has(column) && !t.Get(i, column).empty(); };
  TrackRow r;
  const long long frame = t.GetInt(i, "frame");
  FV_REQUIRE(frame >= 0 && frame <= kMaxFrame, "{}: frame {} is not in [0, {}]", where, frame,
             kMaxFrame);
  r.frame = static_cast<int>(frame);
  r.id = static_cast<int>(t.GetInt(i, "id"));
  r.box = cv::Rect2d(t.GetDouble(i, "bb_left"), t.GetDouble(i, "bb_top"),
                     t.GetDouble(i, "bb_width"), t.GetDouble(i, "bb_height"));
  FV_REQUIRE(BoxWithinPixels(r.box),
             "{}: box {},{},{},{} is not a box in an image (finite, within +-{:.0f} px)", where,
             r.box.x, r.box.y, r.box.width, r.box.height, kMaxBoxPixel);
  FV_REQUIRE(r.box.width >= 0 && r.box.height >= 0, "{}: negative box size", where);
  if (present("conf")) r.conf = t.GetDouble(i, "conf");
  FV_REQUIRE(std::isfinite(r.conf), "{}: conf is not a finite number", where);
  if (has_header) {
    if (present("x_m") && present("y_m")) {
      r.x_m = t.GetDouble(i, "x_m");
      r.y_m = t.GetDouble(i, "y_m");
      FV_REQUIRE(std::abs(*r.x_m) <= kMaxFieldM && std::abs(*r.y_m) <= kMaxFieldM,
                 "{}: field position {}, {} m is not finite or beyond +-{:.0f} m (leave x_m,y_m "
                 "empty when unknown)",
                 where, *r.x_m, *r.y_m, kMaxFieldM);
    }
    if (present("time_s")) {
      r.time_s = t.GetDouble(i, "time_s");
      FV_REQUIRE(std::isfinite(*r.time_s), "{}: time_s is not a finite number", where);
    }
  } else if (t.header().size() == 9) {
    // MOT16/17/20 ground truth: class and visibility.
    r.mot_class = static_cast<int>(t.GetDouble(i, "mot_class"));
    r.visibility = t.GetDouble(i, "mot_visibility");
  }
  return r;
}

}  // namespace

std::vector<TrackRow> ReadTracksCsv(const std::string& path) {
  bool has_header = false;
  const std::string text = ReadTracksText(path, &has_header);
  const util::CsvTable t = has_header ? util::CsvTable::Parse(text, path)
                                      : util::CsvTable::ParseHeaderless(text, path, MotColumns());
  if (has_header) {
    FV_REQUIRE(t.header().size() >= 3 && t.header()[0] == "frame" && t.header()[1] == "id" &&
                   t.header()[2] == "bb_left",
               "{}: header must start with frame,id,bb_left,bb_top,bb_width,bb_height", path);
    for (const char* need : {"bb_top", "bb_width", "bb_height"}) {
      FV_REQUIRE(t.Has(need), "{}: header has no column '{}'", path, need);
    }
  } else {
    FV_REQUIRE(t.rows() == 0 || t.header().size() >= 6, "{}: expected at least 6 columns, got {}",
               t.Where(0), t.header().size());
  }
  std::vector<TrackRow> rows;
  rows.reserve(t.rows());
  for (size_t i = 0; i < t.rows(); ++i) rows.push_back(TrackRowAt(t, i, has_header));
  return rows;
}

void MotOptions::Check() const {
  CheckInRange(iou_threshold, 1e-6, 1.0, "iou_threshold");
  FV_REQUIRE(std::abs(frame_offset) <= 1000000, "frame_offset {} is out of range", frame_offset);
}

// The share of the ground truth's frames outside the estimate's span above which Summary notes
// that the estimate may be of a clip.
constexpr double kClipShare = 0.1;

std::string MotPreprocessing::Summary() const {
  std::string s = fmt::format(
      "left out: {} ground-truth boxes (conf 0 or not a pedestrian), {} estimated boxes on "
      "distractors, {} estimated boxes outside the ground truth's frames",
      gt_ignored, est_on_distractors, est_outside_gt_frames);
  if (gt_outside_est_frames > 0 && gt_clipped) {
    s += fmt::format(", {} ground-truth boxes outside the estimate's frames {}..{}",
                     gt_outside_est_frames, est_first, est_last);
  } else if (gt_frames_outside_est > kClipShare * gt_frames) {
    // A clip, not a tracker's warm-up or a track lost near the end.
    s += fmt::format(
        "; NOTE: the estimate covers frames {}..{} only: {} ground-truth boxes outside them count "
        "as misses (if the estimate is of a clip, --est-frames scores its frames only)",
        est_first, est_last, gt_outside_est_frames);
  }
  if (best_offset != 0 && iou_at_best > 1.02 * iou_at_zero) {
    s += fmt::format(
        "; WARNING: the frames look shifted: the boxes overlap better (summed IoU {:.0f} against "
        "{:.0f}) with the estimate's frames moved by {:+d} (--frame-offset {})",
        iou_at_best, iou_at_zero, best_offset, best_offset);
  }
  return s;
}

std::string MotMetrics::Summary() const {
  return fmt::format(
      "MOTA {:.3f}  MOTP {:.3f}  IDF1 {:.3f}  HOTA {:.3f} (DetA {:.3f}, AssA {:.3f})  "
      "precision {:.3f} recall {:.3f}  TP {} FP {} FN {} IDSW {} frag {}  MT {} ML {} of {} ids "
      "({} estimated)  {} frames",
      mota, motp, idf1, hota, deta, assa, precision, recall, tp, fp, fn, id_switches,
      fragmentations, mostly_tracked, mostly_lost, gt_ids, est_ids, frames);
}

std::string MotMetrics::ToJson() const {
  nlohmann::json j = {{"mota", mota},
                      {"motp", motp},
                      {"idf1", idf1},
                      {"idp", idp},
                      {"idr", idr},
                      {"hota", hota},
                      {"deta", deta},
                      {"assa", assa},
                      {"precision", precision},
                      {"recall", recall},
                      {"tp", tp},
                      {"fp", fp},
                      {"fn", fn},
                      {"id_switches", id_switches},
                      {"fragmentations", fragmentations},
                      {"mostly_tracked", mostly_tracked},
                      {"mostly_lost", mostly_lost},
                      {"gt_ids", gt_ids},
                      {"est_ids", est_ids},
                      {"gt_boxes", gt_boxes},
                      {"est_boxes", est_boxes},
                      {"frames", frames},
                      {"gt_ignored", preprocessing.gt_ignored},
                      {"est_on_distractors", preprocessing.est_on_distractors},
                      {"est_outside_gt_frames", preprocessing.est_outside_gt_frames},
                      {"gt_outside_est_frames", preprocessing.gt_outside_est_frames},
                      {"gt_outside_est_frames_left_out", preprocessing.gt_clipped},
                      {"best_frame_offset", preprocessing.best_offset}};
  return j.dump(2);
}

std::vector<std::pair<int, int>> MatchBoxes(const std::vector<const TrackRow*>& a,
                                            const std::vector<const TrackRow*>& b, double thr) {
  std::vector<std::pair<int, int>> out;
  if (a.empty() || b.empty()) return out;
  std::vector<std::vector<double>> cost(a.size(), std::vector<double>(b.size()));
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = 0; j < b.size(); ++j) {
      const double v = Iou(a[i]->box, b[j]->box);
      cost[i][j] = v >= thr - 1e-12 ? 1.0 - v : 1e9;
    }
  }
  const std::vector<int> m = SolveAssignment(cost);
  for (size_t i = 0; i < a.size(); ++i) {
    if (m[i] >= 0 && cost[i][m[i]] < 1e8) out.emplace_back(static_cast<int>(i), m[i]);
  }
  return out;
}

namespace {

std::map<int, std::vector<const TrackRow*>> ByFrame(const std::vector<TrackRow>& rows,
                                                    int offset = 0) {
  std::map<int, std::vector<const TrackRow*>> out;
  for (const auto& r : rows) out[r.frame + offset].push_back(&r);
  return out;
}

// MOT17 rules, frame alignment check and clipping (MotOptions): the rows that are scored.
void Preprocess(const std::vector<TrackRow>& gt_in, const std::vector<TrackRow>& est_in,
                const MotOptions& o, std::vector<TrackRow>& gt, std::vector<TrackRow>& est,
                MotPreprocessing& p) {
  est = est_in;
  for (auto& r : est) r.frame += o.frame_offset;
  // Frame alignment: summed IoU of the matches (IoU >= 0.5) for offsets -2..2 (on the ground
  // truth as given); slow walkers overlap themselves a frame later, so the IoU, not the count.
  const auto gt_frames = ByFrame(gt_in);
  for (int off = -2; off <= 2; ++off) {
    double sum = 0;
    for (const auto& [f, es] : ByFrame(est, off)) {
      const auto g = gt_frames.find(f);
      if (g == gt_frames.end()) continue;
      for (const auto& [i, j] : MatchBoxes(g->second, es, 0.5)) {
        sum += Iou(g->second[i]->box, es[j]->box);
      }
    }
    if (off == 0) p.iou_at_zero = sum;
    if (sum > p.iou_at_best || (sum == p.iou_at_best && off == 0)) {
      p.iou_at_best = sum;
      p.best_offset = off;
    }
  }
  bool has_classes = false;
  for (const auto& r : gt_in) has_classes = has_classes || r.mot_class >= 0;
  if (o.mot17_rules && has_classes) {
    // TrackEval: estimated boxes matched to a distractor class are removed.
    static const std::set<int> kDistractors = {2, 7, 8, 12};
    std::set<const TrackRow*> drop;
    const auto est_frames = ByFrame(est);
    for (const auto& [f, gs] : gt_frames) {
      const auto e = est_frames.find(f);
      if (e == est_frames.end()) continue;
      for (const auto& [i, j] : MatchBoxes(gs, e->second, 0.5)) {
        if (kDistractors.count(gs[i]->mot_class)) drop.insert(e->second[j]);
      }
    }
    std::vector<TrackRow> kept;
    for (const auto& [f, es] : est_frames) {
      for (const TrackRow* r : es) {
        if (!drop.count(r)) kept.push_back(*r);
      }
    }
    p.est_on_distractors = static_cast<int>(drop.size());
    est = std::move(kept);
    for (const auto& r : gt_in) {
      if (r.conf != 0 && r.mot_class == 1) {
        gt.push_back(r);
      } else {
        p.gt_ignored++;
      }
    }
  } else {
    gt = gt_in;
  }
  if (o.clip_to_gt_frames && !gt_frames.empty()) {
    const int first = gt_frames.begin()->first, last = gt_frames.rbegin()->first;
    const auto outside_gt = [&](const TrackRow& r) { return r.frame < first || r.frame > last; };
    // Scores of 0 from tracks of other frames would read as a tracker that found nobody.
    if (!est.empty() && std::all_of(est.begin(), est.end(), outside_gt)) {
      const auto [lo, hi] = std::minmax_element(
          est.begin(), est.end(),
          [](const TrackRow& a, const TrackRow& b) { return a.frame < b.frame; });
      Throw(
          "no estimated box lies in the ground truth's frames {}..{} (the estimates are in "
          "frames {}..{}): another video's tracks, or a wrong --frame-offset?",
          first, last, lo->frame, hi->frame);
    }
    const size_t before = est.size();
    std::erase_if(est, outside_gt);
    p.est_outside_gt_frames = static_cast<int>(before - est.size());
    p.gt_first = first;
    p.gt_last = last;
    p.est_clipped = true;
  }
  if (!est.empty()) {
    const auto [lo, hi] =
        std::minmax_element(est.begin(), est.end(),
                            [](const TrackRow& a, const TrackRow& b) { return a.frame < b.frame; });
    p.est_first = lo->frame;
    p.est_last = hi->frame;
    const auto outside = [&](const TrackRow& r) {
      return r.frame < p.est_first || r.frame > p.est_last;
    };
    std::set<int> frames, frames_outside;
    for (const TrackRow& r : gt) {
      frames.insert(r.frame);
      if (!outside(r)) continue;
      ++p.gt_outside_est_frames;
      frames_outside.insert(r.frame);
    }
    p.gt_frames = static_cast<int>(frames.size());
    p.gt_frames_outside_est = static_cast<int>(frames_outside.size());
    p.gt_clipped = o.clip_to_est_frames;
    if (p.gt_clipped) std::erase_if(gt, outside);
  }
}

}  // namespace

namespace {

// MOTChallenge allows one box per id and frame; a second would be counted twice.
void CheckOneBoxPerIdAndFrame(const std::vector<TrackRow>& rows, const std::string& what) {
  std::map<std::pair<int, int>, size_t> seen;  // (frame, id) -> row
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto [it, fresh] = seen.emplace(std::pair{rows[i].frame, rows[i].id}, i);
    FV_REQUIRE(fresh,
               "{}: id {} has two boxes in frame {} (rows {} and {}); every id may have one box "
               "per frame",
               what, rows[i].id, rows[i].frame, it->second + 1, i + 1);
  }
}

}  // namespace

MotIndex IndexMotRows(const std::vector<TrackRow>& gt, const std::vector<TrackRow>& est) {
  MotIndex index;
  for (const auto& r : gt) {
    index.frames[r.frame].gt.push_back(&r);
    index.gt_index.emplace(r.id, static_cast<int>(index.gt_index.size()));
  }
  for (const auto& r : est) {
    index.frames[r.frame].est.push_back(&r);
    index.est_index.emplace(r.id, static_cast<int>(index.est_index.size()));
  }
  return index;
}

std::vector<std::vector<double>> FrameIou(const MotFrame& fd) {
  const size_t G = fd.gt.size(), E = fd.est.size();
  std::vector<std::vector<double>> iou(G, std::vector<double>(E));
  for (size_t i = 0; i < G; ++i) {
    for (size_t j = 0; j < E; ++j) iou[i][j] = Iou(fd.gt[i]->box, fd.est[j]->box);
  }
  return iou;
}

std::vector<int> MatchClearMot(const MotFrame& fd, const std::vector<std::vector<double>>& iou,
                               const std::map<int, int>& last_match, double thr) {
  const size_t G = fd.gt.size(), E = fd.est.size();
  std::vector<int> match(G, -1);
  std::vector<char> est_taken(E, 0);
  for (size_t i = 0; i < G; ++i) {
    const auto it = last_match.find(fd.gt[i]->id);
    if (it == last_match.end()) continue;
    for (size_t j = 0; j < E; ++j) {
      if (!est_taken[j] && fd.est[j]->id == it->second && iou[i][j] >= thr) {
        match[i] = static_cast<int>(j);
        est_taken[j] = 1;
      }
    }
  }
  std::vector<int> rows_left, cols_left;
  for (size_t i = 0; i < G; ++i) {
    if (match[i] < 0) rows_left.push_back(static_cast<int>(i));
  }
  for (size_t j = 0; j < E; ++j) {
    if (!est_taken[j]) cols_left.push_back(static_cast<int>(j));
  }
  std::vector<std::vector<double>> cost(rows_left.size(), std::vector<double>(cols_left.size()));
  for (size_t a = 0; a < rows_left.size(); ++a) {
    for (size_t b = 0; b < cols_left.size(); ++b) {
      const double v = iou[rows_left[a]][cols_left[b]];
      cost[a][b] = v >= thr ? 1.0 - v : 1e9;
    }
  }
  const std::vector<int> assign = SolveAssignment(cost);
  for (size_t a = 0; a < rows_left.size(); ++a) {
    if (assign[a] >= 0) match[rows_left[a]] = cols_left[assign[a]];
  }
  return match;
}

MotIdCounts CountClearMot(const MotIndex& index, double thr, MotMetrics& m) {
  const int ng = static_cast<int>(index.gt_index.size());
  const int ne = static_cast<int>(index.est_index.size());
  MotIdCounts c;
  c.pair_frames.assign(ng, std::vector<int>(ne, 0));
  c.potential.assign(ng, std::vector<double>(ne, 0.0));
  c.gt_count.assign(ng, 0);
  c.est_count.assign(ne, 0);
  std::map<int, int> last_match;          // gt id -> est id of its last match
  std::map<int, int> last_matched_frame;  // gt id -> frame index of its last match (fragments)
  std::map<int, int> gt_frames, gt_matched;
  double iou_sum = 0;
  int frame_idx = 0;
  for (const auto& [frame, fd] : index.frames) {
    ++frame_idx;
    const size_t G = fd.gt.size(), E = fd.est.size();
    const std::vector<std::vector<double>> iou = FrameIou(fd);
    // HOTA: similarity normalised by row and column sums (TrackEval).
    std::vector<double> row_sum(G, 0), col_sum(E, 0);
    for (size_t i = 0; i < G; ++i) {
      for (size_t j = 0; j < E; ++j) {
        row_sum[i] += iou[i][j];
        col_sum[j] += iou[i][j];
      }
    }
    for (size_t i = 0; i < G; ++i) {
      const int g = index.gt_index.at(fd.gt[i]->id);
      c.gt_count[g]++;
      for (size_t j = 0; j < E; ++j) {
        const double denom = row_sum[i] + col_sum[j] - iou[i][j];
        if (denom > 0) c.potential[g][index.est_index.at(fd.est[j]->id)] += iou[i][j] / denom;
      }
    }
    for (size_t j = 0; j < E; ++j) c.est_count[index.est_index.at(fd.est[j]->id)]++;
    const std::vector<int> match = MatchClearMot(fd, iou, last_match, thr);
    int tp = 0;
    for (size_t i = 0; i < G; ++i) {
      const int gid = fd.gt[i]->id;
      gt_frames[gid]++;
      if (match[i] < 0) continue;
      ++tp;
      gt_matched[gid]++;
      iou_sum += iou[i][match[i]];
      const int eid = fd.est[match[i]]->id;
      const auto it = last_match.find(gid);
      if (it != last_match.end() && it->second != eid) m.id_switches++;
      const auto lf = last_matched_frame.find(gid);
      if (lf != last_matched_frame.end() && lf->second != frame_idx - 1) m.fragmentations++;
      last_match[gid] = eid;
      last_matched_frame[gid] = frame_idx;
    }
    m.tp += tp;
    m.fp += static_cast<int>(E) - tp;
    m.fn += static_cast<int>(G) - tp;
    // IDF1: frames where a gt id and an est id overlap enough (any pairing, per frame).
    for (size_t i = 0; i < G; ++i) {
      for (size_t j = 0; j < E; ++j) {
        if (iou[i][j] >= thr) {
          c.pair_frames[index.gt_index.at(fd.gt[i]->id)][index.est_index.at(fd.est[j]->id)]++;
        }
      }
    }
  }
  m.mota = m.gt_boxes > 0 ? 1.0 - double(m.fn + m.fp + m.id_switches) / m.gt_boxes : 0.0;
  m.motp = m.tp > 0 ? iou_sum / m.tp : 0.0;
  m.precision = m.est_boxes > 0 ? double(m.tp) / m.est_boxes : 0.0;
  m.recall = m.gt_boxes > 0 ? double(m.tp) / m.gt_boxes : 0.0;
  for (const auto& [gid, n] : gt_frames) {
    const double cover = double(gt_matched[gid]) / n;
    if (cover >= 0.8) m.mostly_tracked++;
    if (cover <= 0.2) m.mostly_lost++;
  }
  return c;
}

void ScoreIdentity(const std::vector<std::vector<int>>& pair_frames, MotMetrics& m) {
  const int ng = static_cast<int>(pair_frames.size());
  const int ne = ng > 0 ? static_cast<int>(pair_frames[0].size()) : 0;
  if (ng == 0 || ne == 0) return;
  std::vector<std::vector<double>> cost(ng, std::vector<double>(ne));
  for (int g = 0; g < ng; ++g) {
    for (int e = 0; e < ne; ++e) cost[g][e] = pair_frames[g][e] > 0 ? -pair_frames[g][e] : 1e9;
  }
  const std::vector<int> a = SolveAssignment(cost);
  double idtp = 0;
  for (int g = 0; g < ng; ++g) {
    if (a[g] >= 0) idtp += pair_frames[g][a[g]];
  }
  m.idf1 = 2 * idtp / (m.gt_boxes + m.est_boxes);
  m.idp = idtp / m.est_boxes;
  m.idr = idtp / m.gt_boxes;
}

void ScoreHota(const MotIndex& index, const MotIdCounts& c, MotMetrics& m) {
  const int ng = static_cast<int>(c.gt_count.size()), ne = static_cast<int>(c.est_count.size());
  if (ng == 0 || ne == 0) return;
  // Per frame, match by global alignment x IoU; count per alpha.
  std::vector<std::vector<double>> align(ng, std::vector<double>(ne, 0));
  for (int g = 0; g < ng; ++g) {
    for (int e = 0; e < ne; ++e) {
      align[g][e] = c.potential[g][e] / (c.gt_count[g] + c.est_count[e] - c.potential[g][e]);
    }
  }
  constexpr int kAlphas = 19;
  std::vector<double> tp_a(kAlphas, 0);
  std::vector<std::vector<std::vector<int>>> matches(
      kAlphas, std::vector<std::vector<int>>(ng, std::vector<int>(ne, 0)));
  for (const auto& [frame, fd] : index.frames) {
    const size_t G = fd.gt.size(), E = fd.est.size();
    if (G == 0 || E == 0) continue;
    const std::vector<std::vector<double>> iou = FrameIou(fd);
    std::vector<std::vector<double>> cost(G, std::vector<double>(E));
    for (size_t i = 0; i < G; ++i) {
      for (size_t j = 0; j < E; ++j) {
        const double s =
            align[index.gt_index.at(fd.gt[i]->id)][index.est_index.at(fd.est[j]->id)] * iou[i][j];
        cost[i][j] = s > 0 ? -s : 1e9;
      }
    }
    const std::vector<int> a = SolveAssignment(cost);
    for (size_t i = 0; i < G; ++i) {
      if (a[i] < 0) continue;
      for (int k = 0; k < kAlphas; ++k) {
        const double alpha = 0.05 + 0.05 * k;
        if (iou[i][a[i]] >= alpha - 1e-9) {
          tp_a[k] += 1;
          matches[k][index.gt_index.at(fd.gt[i]->id)][index.est_index.at(fd.est[a[i]]->id)]++;
        }
      }
    }
  }
  double hota = 0, deta = 0, assa = 0;
  for (int k = 0; k < kAlphas; ++k) {
    const double tp = tp_a[k];
    const double fn = m.gt_boxes - tp, fp = m.est_boxes - tp;
    const double det = tp / std::max(1.0, tp + fn + fp);
    double ass = 0;
    for (int g = 0; g < ng; ++g) {
      for (int e = 0; e < ne; ++e) {
        const int n = matches[k][g][e];
        if (n == 0) continue;
        ass += n * (double(n) / (c.gt_count[g] + c.est_count[e] - n));
      }
    }
    ass /= std::max(1.0, tp);
    hota += std::sqrt(det * ass);
    deta += det;
    assa += ass;
  }
  m.hota = hota / kAlphas;
  m.deta = deta / kAlphas;
  m.assa = assa / kAlphas;
}

void MotPreprocessing::ClipAsScored(std::vector<TrackRow>& gt, std::vector<TrackRow>& est,
                                    int frame_offset) const {
  if (gt_clipped) {
    std::erase_if(gt, [&](const TrackRow& r) { return r.frame < est_first || r.frame > est_last; });
  }
  if (est_clipped) {
    std::erase_if(est, [&](const TrackRow& r) {
      return r.frame + frame_offset < gt_first || r.frame + frame_offset > gt_last;
    });
  }
}

MotMetrics EvaluateMot(const std::vector<TrackRow>& gt_in, const std::vector<TrackRow>& est_in,
                       const MotOptions& options) {
  options.Check();
  CheckOneBoxPerIdAndFrame(gt_in, "ground truth");
  CheckOneBoxPerIdAndFrame(est_in, "estimate");
  std::vector<TrackRow> gt, est;
  MotPreprocessing pre;
  Preprocess(gt_in, est_in, options, gt, est, pre);
  const MotIndex index = IndexMotRows(gt, est);
  MotMetrics m;
  m.preprocessing = pre;
  m.frames = static_cast<int>(index.frames.size());
  m.gt_boxes = static_cast<int>(gt.size());
  m.est_boxes = static_cast<int>(est.size());
  m.gt_ids = static_cast<int>(index.gt_index.size());
  m.est_ids = static_cast<int>(index.est_index.size());
  // The id-pair tables hold gt_ids x est_ids counts.
  FV_REQUIRE(static_cast<double>(m.gt_ids) * m.est_ids <= 5e7,
             "eval tracks: {} ground-truth ids x {} estimated ids is too many id pairs to score "
             "(at most 5e7)",
             m.gt_ids, m.est_ids);
  const MotIdCounts counts = CountClearMot(index, options.iou_threshold, m);
  ScoreIdentity(counts.pair_frames, m);
  ScoreHota(index, counts, m);
  return m;
}

}  // namespace fv::track
