#include "fieldvision/track/mot.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "fieldvision/track/detection.h"
#include "fieldvision/track/hungarian.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::track {

void WriteTracksCsv(const std::vector<TrackRow>& rows, const std::string& path) {
  CsvWriter w(
      path, {"frame", "id", "bb_left", "bb_top", "bb_width", "bb_height", "conf", "x_m", "y_m"}, 4);
  for (const auto& r : rows) {
    w << r.frame << r.id << r.box.x << r.box.y << r.box.width << r.box.height << r.conf;
    if (r.x_m && r.y_m) {
      w << *r.x_m << *r.y_m;
    } else {
      w << ""
        << "";
    }
    w.EndRow();
  }
  w.Close();
}

std::vector<TrackRow> ReadTracksCsv(const std::string& path) {
  std::ifstream in(path);
  FV_REQUIRE(in.good(), "cannot open tracks file '{}'", path);
  std::vector<TrackRow> rows;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = Trim(line);
    if (t.empty()) continue;
    if (line_no == 1 && !t.empty() && !std::isdigit(static_cast<unsigned char>(t[0])) &&
        t[0] != '-') {
      FV_REQUIRE(StartsWith(t, "frame,id,bb_left"),
                 "{}: header must start with frame,id,bb_left,bb_top,bb_width,bb_height", path);
      continue;
    }
    const std::vector<std::string> f = Split(t, ',');
    FV_REQUIRE(f.size() >= 6, "{}:{}: expected at least 6 columns, got {}", path, line_no,
               f.size());
    const std::string where = fmt::format("{}:{}", path, line_no);
    TrackRow r;
    r.frame = static_cast<int>(ParseInt(Trim(f[0]), where + " frame"));
    r.id = static_cast<int>(ParseInt(Trim(f[1]), where + " id"));
    r.box = cv::Rect2d(ParseDouble(Trim(f[2]), where + " bb_left"),
                       ParseDouble(Trim(f[3]), where + " bb_top"),
                       ParseDouble(Trim(f[4]), where + " bb_width"),
                       ParseDouble(Trim(f[5]), where + " bb_height"));
    FV_REQUIRE(r.box.width >= 0 && r.box.height >= 0, "{}: negative box size", where);
    if (f.size() > 6 && !Trim(f[6]).empty()) r.conf = ParseDouble(Trim(f[6]), where + " conf");
    if (f.size() > 8 && !Trim(f[7]).empty() && !Trim(f[8]).empty()) {
      r.x_m = ParseDouble(Trim(f[7]), where + " x_m");
      r.y_m = ParseDouble(Trim(f[8]), where + " y_m");
    }
    rows.push_back(r);
  }
  return rows;
}

void MotOptions::Check() const { CheckInRange(iou_threshold, 1e-6, 1.0, "iou_threshold"); }

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
                      {"frames", frames}};
  return j.dump(2);
}

namespace {

struct FrameData {
  std::vector<const TrackRow*> gt, est;
};

}  // namespace

MotMetrics EvaluateMot(const std::vector<TrackRow>& gt, const std::vector<TrackRow>& est,
                       const MotOptions& options) {
  options.Check();
  std::map<int, FrameData> frames;
  std::map<int, int> gt_index, est_index;  // id -> dense index
  for (const auto& r : gt) {
    frames[r.frame].gt.push_back(&r);
    gt_index.emplace(r.id, static_cast<int>(gt_index.size()));
  }
  for (const auto& r : est) {
    frames[r.frame].est.push_back(&r);
    est_index.emplace(r.id, static_cast<int>(est_index.size()));
  }
  MotMetrics m;
  m.frames = static_cast<int>(frames.size());
  m.gt_boxes = static_cast<int>(gt.size());
  m.est_boxes = static_cast<int>(est.size());
  m.gt_ids = static_cast<int>(gt_index.size());
  m.est_ids = static_cast<int>(est_index.size());
  const int ng = m.gt_ids, ne = m.est_ids;
  const double thr = options.iou_threshold;

  // CLEAR MOT and the per-id-pair counts for IDF1, and HOTA's similarity sums.
  std::map<int, int> last_match;          // gt id -> est id of its last match
  std::map<int, int> last_matched_frame;  // gt id -> frame index of its last match (fragments)
  std::map<int, int> gt_frames, gt_matched;
  std::vector<std::vector<int>> pair_frames(ng, std::vector<int>(ne, 0));
  std::vector<std::vector<double>> potential(ng, std::vector<double>(ne, 0.0));
  std::vector<int> gt_count(ng, 0), est_count(ne, 0);
  double iou_sum = 0;
  int frame_idx = 0;
  for (auto& [frame, fd] : frames) {
    ++frame_idx;
    const size_t G = fd.gt.size(), E = fd.est.size();
    std::vector<std::vector<double>> iou(G, std::vector<double>(E));
    for (size_t i = 0; i < G; ++i) {
      for (size_t j = 0; j < E; ++j) iou[i][j] = Iou(fd.gt[i]->box, fd.est[j]->box);
    }
    // HOTA: similarity normalised by row and column sums (TrackEval).
    std::vector<double> row_sum(G, 0), col_sum(E, 0);
    for (size_t i = 0; i < G; ++i) {
      for (size_t j = 0; j < E; ++j) {
        row_sum[i] += iou[i][j];
        col_sum[j] += iou[i][j];
      }
    }
    for (size_t i = 0; i < G; ++i) {
      const int g = gt_index[fd.gt[i]->id];
      gt_count[g]++;
      for (size_t j = 0; j < E; ++j) {
        const double denom = row_sum[i] + col_sum[j] - iou[i][j];
        if (denom > 0) potential[g][est_index[fd.est[j]->id]] += iou[i][j] / denom;
      }
    }
    for (size_t j = 0; j < E; ++j) est_count[est_index[fd.est[j]->id]]++;
    // CLEAR MOT: keep last frame's valid pairs, Hungarian on the rest.
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
        if (iou[i][j] >= thr) pair_frames[gt_index[fd.gt[i]->id]][est_index[fd.est[j]->id]]++;
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
  // IDF1: maximise the total matched frames over one-to-one id pairs.
  if (ng > 0 && ne > 0) {
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
  // HOTA (second pass): per frame, match by global alignment x IoU; count per alpha.
  if (ng > 0 && ne > 0) {
    std::vector<std::vector<double>> align(ng, std::vector<double>(ne, 0));
    for (int g = 0; g < ng; ++g) {
      for (int e = 0; e < ne; ++e) {
        align[g][e] = potential[g][e] / (gt_count[g] + est_count[e] - potential[g][e]);
      }
    }
    constexpr int kAlphas = 19;
    std::vector<double> tp_a(kAlphas, 0);
    std::vector<std::vector<std::vector<int>>> matches(
        kAlphas, std::vector<std::vector<int>>(ng, std::vector<int>(ne, 0)));
    for (auto& [frame, fd] : frames) {
      const size_t G = fd.gt.size(), E = fd.est.size();
      if (G == 0 || E == 0) continue;
      std::vector<std::vector<double>> cost(G, std::vector<double>(E));
      std::vector<std::vector<double>> iou(G, std::vector<double>(E));
      for (size_t i = 0; i < G; ++i) {
        for (size_t j = 0; j < E; ++j) {
          iou[i][j] = Iou(fd.gt[i]->box, fd.est[j]->box);
          const double s = align[gt_index[fd.gt[i]->id]][est_index[fd.est[j]->id]] * iou[i][j];
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
            matches[k][gt_index[fd.gt[i]->id]][est_index[fd.est[a[i]]->id]]++;
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
          const int c = matches[k][g][e];
          if (c == 0) continue;
          ass += c * (double(c) / (gt_count[g] + est_count[e] - c));
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
  return m;
}

}  // namespace fv::track
