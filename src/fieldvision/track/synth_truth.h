// `synth`'s truth of the people as ground truth for `eval tracks`: players_2d.csv (frame, cam,
// id, box, visible_fraction; frames from 0) for one camera, with the field positions and times of
// players.csv beside it where that file is there, frames numbered from 1 as TRACKS.csv's.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/track/mot.h"

namespace fv::track {

// Whether `path` is a CSV whose header is players_2d.csv's.
bool IsSynthPeopleTruth(const std::string& path);

// The rows of camera `cam` ("" = the file's only camera; a file of several cameras then throws
// naming them) of people at least `min_visible` visible, visibility kept. Throws fv::Error naming
// the file and line for anything malformed.
std::vector<TrackRow> ReadSynthPeopleTruth(const std::string& path, const std::string& cam = "",
                                           double min_visible = 0.2);

}  // namespace fv::track
