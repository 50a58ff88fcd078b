// Accuracy of a ball track against ground truth, as in the seeds' error tables: estimates and
// truth matched by frame, the 3D error of each in millimetres, then mean, median, 95th
// percentile and maximum, the share of frames found among those at least `min_truth_cams`
// cameras see, and the estimates further off than `outlier_m` (false estimates).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "fieldvision/util/csv.h"

namespace fv::recon {

struct BallEvalOptions {
  int min_truth_cams = 2;  // truth frames that count for the found rate (truth n_cams >= this)
  double outlier_m = 0.5;  // an estimate further off than this is a false estimate
  void Check() const;      // throws fv::Error naming the bad field
};

struct BallErrorRow {
  long long frame = 0;
  double time_s = 0.0;
  Eigen::Vector3d truth_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d est_m = Eigen::Vector3d::Zero();
  int truth_n_cams = -1;  // -1 when the truth has no n_cams column
  int est_n_cams = -1;
  double err_mm = 0.0;
};

struct BallEvalResult {
  std::vector<BallErrorRow> rows;  // matched frames, in frame order
  long long truth_frames = 0;
  long long visible_frames = 0;  // truth frames with n_cams >= min_truth_cams
  long long visible_found = 0;   // of those, frames with an estimate
  long long estimates = 0;       // rows of the estimate file
  long long estimates_without_truth = 0;
  long long outliers = 0;  // matched estimates further off than outlier_m
  double mean_mm = 0, median_mm = 0, p95_mm = 0, max_mm = 0;
  BallEvalOptions options;  // the options used
  double found_fraction() const {
    return visible_frames ? static_cast<double>(visible_found) / visible_frames : 0.0;
  }
  // The table: one line per matched frame when `per_row` (x, y, z truth and estimate, error in
  // mm), then the summary lines.
  std::string Table(bool per_row) const;
};

// Truth needs frame,x_m,y_m,z_m (time_s and n_cams optional); the estimate frame,x_m,y_m,z_m
// (time_s, n_cams optional). Throws fv::Error naming the file and line for missing columns,
// non-finite values or a frame listed twice.
BallEvalResult EvaluateBall(const util::CsvTable& truth, const util::CsvTable& est,
                            const BallEvalOptions& options = {});
BallEvalResult EvaluateBallFiles(const std::string& truth_csv, const std::string& est_csv,
                                 const BallEvalOptions& options = {});

}  // namespace fv::recon
