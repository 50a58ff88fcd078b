// Checks of input files that the subcommands share before any work: a TRACKS.csv without a
// player twice in one frame (ball tracks: recon/ball_csv.h CheckBallTrackRanges).
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

}  // namespace fv::app
