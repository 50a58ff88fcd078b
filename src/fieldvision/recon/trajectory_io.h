// Ball tracks on disk and flights as JSON: reads BALL.csv (`frame,time_s,x_m,y_m,z_m,n_cams,
// err_px`, CONTRACT.md) or the TT3D layout (`Timestamp,X,Y,Z`), naming and skipping bad rows
// (not numbers, NaN, times not increasing, duplicates); writes tracks and the flights JSON.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/util/csv.h"

namespace fv {

struct BallTrackFile {
  std::vector<BallSample> samples;   // strictly increasing times
  std::string layout;                // "ball" (BALL.csv) or "tt3d" (Timestamp,X,Y,Z)
  std::vector<std::string> skipped;  // one "file:line: reason" per skipped row
};

// Throws fv::Error naming the file when columns are missing, no row is valid or most rows are
// out of time order; skips (and names) single bad rows.
BallTrackFile ParseBallTrack(const CsvTable& table);
BallTrackFile ReadBallTrack(const std::string& path);
// Writes BALL.csv (the contract's header).
void WriteBallTrack(const std::string& path, const std::vector<BallSample>& samples);

nlohmann::json Vec3Json(const Eigen::Vector3d& v, int decimals = 4);
// The contract's flight fields plus events, seen span, speed, flight time, both fits and the
// seed's method.
nlohmann::json FlightToJson(const Flight& f);
// With options: per flight that lands, the velocity and spin after the bounce that the bounce
// model (options->bounce) predicts; per bounce seen on both sides, the measured restitution,
// friction and spin change.
nlohmann::json FlightsToJson(const TrajectoryResult& result,
                             const TrajectoryOptions* options = nullptr);

}  // namespace fv
