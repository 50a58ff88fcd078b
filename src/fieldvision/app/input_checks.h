// Checks of input files that the subcommands share before any work (issue 18): a TRACKS.csv
// without a player twice in one frame, and the numbers of a ball track (BALL.csv, truth) in the
// ranges of a real recording, each error naming the file and line.
#pragma once

#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "fieldvision/recon/ball_csv.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"

namespace fv::app {

// Throws naming `path` when one player id (>= 0; -1 is "no id") has two rows in one frame.
inline void CheckOneRowPerPlayerFrame(const std::vector<track::TrackRow>& rows,
                                      const std::string& path) {
  std::set<std::pair<int, int>> seen;
  for (const auto& r : rows) {
    if (r.id < 0) continue;
    FV_REQUIRE(seen.emplace(r.frame, r.id).second,
               "'{}': player {} has two rows in frame {} (a duplicated row?)", path, r.id, r.frame);
  }
}

// Frame numbers in [0, 1e8], positions within 10 km, times finite and within 1e11 s (Unix time
// fits) in every row of a ball track table; throws naming file:line and the column.
inline void CheckBallTrackRanges(const CsvTable& table) {
  constexpr double kMaxFrame = 1e8, kMaxPositionM = 1e4, kMaxTimeS = 1e11;
  for (size_t r = 0; r < table.rows(); ++r) {
    const BallSample s = ReadBallCsvRow(table, r);
    if (table.Has("frame")) {
      FV_REQUIRE(s.frame >= 0 && s.frame <= kMaxFrame, "{}: frame {} is not in [0, {:.0f}]",
                 table.Where(r), s.frame, kMaxFrame);
    }
    for (int k = 0; k < 3; ++k) {
      FV_REQUIRE(std::abs(s.ball_in_world[k]) <= kMaxPositionM,
                 "{}: {} = {} is not a finite position within +-{:.0f} m", table.Where(r),
                 "xyz"[k] + std::string("_m"), s.ball_in_world[k], kMaxPositionM);
    }
    if (table.Has("time_s") && !table.Get(r, "time_s").empty()) {
      FV_REQUIRE(std::abs(s.time_s) <= kMaxTimeS, "{}: time_s = {} is not a finite time",
                 table.Where(r), s.time_s);
    }
  }
}

}  // namespace fv::app
