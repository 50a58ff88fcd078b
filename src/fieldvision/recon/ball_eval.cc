#include "fieldvision/recon/ball_eval.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "fieldvision/recon/ball_csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace fv::recon {
namespace {

// A truth or estimate file by frame (BALL.csv columns; frame and x_m, y_m, z_m required); n_cams
// is -1 when the file has no such column.
std::map<long long, BallSample> ReadTrack(const util::CsvTable& t) {
  t.Require({"frame", "x_m", "y_m", "z_m"});
  std::map<long long, BallSample> out;
  for (size_t r = 0; r < t.rows(); ++r) {
    BallSample s = ReadBallCsvRow(t, r);
    FV_REQUIRE(s.frame >= 0, "{}: frame must be >= 0", t.Where(r));
    FV_REQUIRE(s.ball_in_world.allFinite(), "{}: x_m, y_m, z_m must be finite numbers", t.Where(r));
    if (!t.Has("n_cams")) s.n_cams = -1;
    FV_REQUIRE(out.emplace(s.frame, s).second, "{}: frame {} is listed twice", t.Where(r), s.frame);
  }
  return out;
}

}  // namespace

void BallEvalOptions::Check() const {
  FV_REQUIRE(min_truth_cams >= 0, "BallEvalOptions.min_truth_cams must be >= 0 (got {})",
             min_truth_cams);
  CheckPositive(outlier_m, "BallEvalOptions.outlier_m");
}

BallEvalResult EvaluateBall(const util::CsvTable& truth_table, const util::CsvTable& est_table,
                            const BallEvalOptions& options) {
  options.Check();
  const auto truth = ReadTrack(truth_table);
  const auto est = ReadTrack(est_table);
  BallEvalResult r;
  r.options = options;
  r.truth_frames = static_cast<long long>(truth.size());
  r.estimates = static_cast<long long>(est.size());
  std::vector<double> errs;
  for (const auto& [frame, t] : truth) {
    const bool visible = t.n_cams < 0 || t.n_cams >= options.min_truth_cams;
    if (visible) ++r.visible_frames;
    const auto it = est.find(frame);
    if (it == est.end()) continue;
    if (visible) ++r.visible_found;
    BallErrorRow row;
    row.frame = frame;
    row.time_s = t.time_s;
    row.truth_m = t.ball_in_world;
    row.est_m = it->second.ball_in_world;
    row.truth_n_cams = t.n_cams;
    row.est_n_cams = it->second.n_cams;
    row.err_mm = 1000.0 * (row.est_m - row.truth_m).norm();
    if (row.err_mm > 1000.0 * options.outlier_m) ++r.outliers;
    errs.push_back(row.err_mm);
    r.rows.push_back(row);
  }
  for (const auto& [frame, e] : est) {
    if (!truth.count(frame)) ++r.estimates_without_truth;
  }
  if (!errs.empty()) {
    r.mean_mm = util::Mean(errs);
    r.median_mm = util::Percentile(errs, 0.5);
    r.p95_mm = util::Percentile(errs, 0.95);
    r.max_mm = *std::max_element(errs.begin(), errs.end());
  }
  return r;
}

BallEvalResult EvaluateBallFiles(const std::string& truth_csv, const std::string& est_csv,
                                 const BallEvalOptions& options) {
  return EvaluateBall(util::CsvTable::Read(truth_csv), util::CsvTable::Read(est_csv), options);
}

std::string BallEvalResult::Table(bool per_row) const {
  std::string s;
  if (per_row) {
    s += fmt::format("{:>6} {:>8} {:>23} {:>23} {:>5} {:>9}\n", "frame", "time_s",
                     "truth x,y,z [m]", "estimate x,y,z [m]", "cams", "error mm");
    for (const auto& r : rows) {
      s += fmt::format(
          "{:>6} {:>8.3f} {:>7.3f},{:>7.3f},{:>7.3f} {:>7.3f},{:>7.3f},{:>7.3f} {:>5} "
          "{:>9.1f}\n",
          r.frame, r.time_s, r.truth_m.x(), r.truth_m.y(), r.truth_m.z(), r.est_m.x(), r.est_m.y(),
          r.est_m.z(), r.est_n_cams, r.err_mm);
    }
  }
  s += fmt::format(
      "matched {} of {} truth frames; found {} of {} frames seen by >= {} cameras "
      "({:.2f} %); {} estimates without truth\n",
      rows.size(), truth_frames, visible_found, visible_frames, options.min_truth_cams,
      100.0 * found_fraction(), estimates_without_truth);
  if (rows.empty()) {
    s += "error mm: none (no estimate has a truth frame to compare with)";
    return s;
  }
  s += fmt::format(
      "error mm: mean {:.2f}, median {:.2f}, p95 {:.2f}, max {:.2f}; {} estimates "
      "more than {} m off",
      mean_mm, median_mm, p95_mm, max_mm, outliers, options.outlier_m);
  return s;
}

}  // namespace fv::recon
