// The `fieldvision trajectory` job: reads a ball track (BALL.csv or TT3D CSV), finds and fits the
// flights (trajectory.h), predicts each landing from the first part of its flight, makes the
// referee calls on a field (trajectory_decisions.h), writes FLIGHTS.json (CONTRACT.md), pictures,
// a smoothed BALL.csv and a report, and prints the flights and a timeline.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/trajectory_decisions.h"
#include "fieldvision/recon/trajectory_io.h"
#include "fieldvision/recon/trajectory_predict.h"

namespace fv::recon {

struct TrajectoryJob {
  std::string in_path;           // BALL.csv or Timestamp,X,Y,Z
  std::string out_path;          // FLIGHTS.json
  double ball_diameter_m = 0.0;  // 0: 0.22 m (football), 0.04 m for the TT3D layout
  double ball_mass_kg = 0.0;     // 0: the standard ball's nearest the diameter (standard_balls.h)
  TrajectoryOptions analysis;    // ball_radius_m is set from the diameter
  // Unmodelled acceleration allowed at breaks; 0: 10 m/s^2 (football), 25 for the TT3D layout
  // (a 2.7 g ball with strong drag and spin).
  double accel_slack_mps2 = 0.0;
  std::string field;  // built-in name or JSON; empty: no calls
  DecisionOptions decisions;
  std::string images_dir;         // empty: no pictures
  std::string smoothed_path;      // empty: no smoothed track
  std::string report_path;        // empty: no report JSON
  double predict_fraction = 0.5;  // of each flight's time used for the landing prediction
  SmootherOptions smoother;
  void Check() const;
};

struct TrajectoryJobResult {
  BallTrackFile input;
  TrajectoryOptions options;  // as used (radius)
  TrajectoryResult result;
  std::vector<LandingPrediction> predictions;  // per flight
  Decisions decisions;
  std::vector<std::string> images;  // written
};

TrajectoryJobResult RunTrajectory(const TrajectoryJob& job, std::ostream& log);

// The flights as a console table; extrapolated origins and landings are marked with '*'.
std::string FlightTable(const TrajectoryResult& result);

// The track files named by a folder (its *.csv files) or a glob pattern (`dir/*.csv`), sorted;
// empty when `in` names a single file. Throws fv::Error when a folder or pattern matches nothing.
std::vector<std::string> ExpandTrackInputs(const std::string& in);

// Batch mode: the job for every file (job.out_path is a folder: NAME.json per track, pictures in
// images_dir/NAME/), then one summary table, summary.csv in that folder, one row per flight (file,
// events, times, origin and landing with their extrapolated flags, model, residuals, spin) and,
// for tracks with a bounce, the pre-bounce scores of trajectory_eval.h printed to `log`.
struct TrajectoryBatchResult {
  std::vector<std::string> files;
  std::vector<std::string> failed;  // "file: error"
  std::string summary_csv;
};
TrajectoryBatchResult RunTrajectoryBatch(const TrajectoryJob& job,
                                         const std::vector<std::string>& files, std::ostream& log);

}  // namespace fv::recon
