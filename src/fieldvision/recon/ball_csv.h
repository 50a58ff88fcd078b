// BALL.csv, the ball track file of CONTRACT.md (`frame,time_s,x_m,y_m,z_m,n_cams,err_px`; truth
// files use the same columns), and the TT3D layout (`Timestamp,X,Y,Z`): the one reader and
// writer that every ball-track user in recon goes through.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/recon/trajectory.h"
#include "fieldvision/util/csv.h"

namespace fv::recon {

// frame,time_s,x_m,y_m,z_m,n_cams,err_px
const std::vector<std::string>& BallCsvColumns();

// Row r of a BALL.csv table: x_m, y_m, z_m and, where the table has the column, frame, time_s,
// n_cams and err_px (BallSample's defaults otherwise). Throws fv::Error naming the file and line
// for a cell that is not a number; finiteness is the caller's to check.
BallSample ReadBallCsvRow(const util::CsvTable& table, size_t r);

// Every row of a ball track table (BALL.csv, truth) in the ranges of a real recording: frame
// numbers in [0, 1e8], positions within 10 km, times finite and within 1e11 s (Unix time fits).
// Throws fv::Error naming file:line and the column.
void CheckBallTrackRanges(const util::CsvTable& table);

struct BallTrackFile {
  std::vector<BallSample> samples;   // strictly increasing times
  std::string layout;                // "ball" (BALL.csv) or "tt3d" (Timestamp,X,Y,Z)
  std::vector<std::string> skipped;  // one "file:line: reason" per skipped row
};

// A ball track for fitting flights: throws fv::Error naming the file when columns are missing, no
// row is valid or most rows are out of time order; skips (and names) single bad rows (not
// numbers, NaN, positions beyond 10 km, times not increasing, duplicates) and checks the units
// (CheckBallTrackUnits).
BallTrackFile ParseBallTrack(const util::CsvTable& table);
// Throws fv::Error naming `name` when the samples are not in seconds and metres: the median step
// 1 s or more (milliseconds), or the median speed over 0.2 s 150 m/s or more (millimetres).
void CheckBallTrackUnits(const std::vector<BallSample>& samples, const std::string& name);
BallTrackFile ReadBallTrack(const std::string& path);
// Writes BALL.csv (BallCsvColumns()).
void WriteBallTrack(const std::string& path, const std::vector<BallSample>& samples);

}  // namespace fv::recon
