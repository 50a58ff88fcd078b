// Identities a coach fixes by hand: a small JSON file of edits applied to TRACKS.csv before
// `stats` (`fieldvision tracks edit`), and the roster file beside TRACKS.csv (TRACKS.csv.teams.csv:
// id,team,name) that carries teams and names. The edits file is an array applied in order, each
// element one operation on the ids as they are at that point:
//   {"merge": [3, 17, 22]}           ids 17 and 22 become 3 (one person tracked in pieces; where
//                                    two were tracked in the same frame, the surer box is kept;
//                                    more than 10 such frames is an error: two people)
//   {"rename": {"3": 10}}            id 3 becomes 10 (a shirt number); 10 must be free
//   {"name": {"10": "Anna"}}         roster names
//   {"team": {"10": 0, "11": 1}}     teams (0, 1, ...; -1: none)
//   {"drop": [5, 9]}                 remove ids (a referee, a bystander, a false track)
// Errors name the file and the line of the edit ("edits.json:4: merge: id 99 is not in the
// tracks").
#pragma once

#include <map>
#include <string>
#include <vector>

#include "fieldvision/track/mot.h"

namespace fv::track {

struct TrackEdit {
  enum class Kind { kMerge, kRename, kName, kTeam, kDrop };
  Kind kind = Kind::kMerge;
  int line = 0;                      // line of the edit in its file (1-based)
  std::vector<int> ids;              // merge (first is kept), drop
  std::map<int, int> to;             // rename: id -> new id; team: id -> team
  std::map<int, std::string> names;  // name: id -> name
};

struct TrackEdits {
  std::string path;  // for messages
  std::vector<TrackEdit> edits;
};

// Parses an edits file's text; `path` names it in errors ("path:line: what").
TrackEdits ParseTrackEdits(const std::string& text, const std::string& path);
// Reads and parses `path`.
TrackEdits ReadTrackEdits(const std::string& path);

// Teams and names by id.
struct Roster {
  std::map<int, int> team_of;
  std::map<int, std::string> name_of;
};

// The roster file beside TRACKS.csv: `id,team[,name]` with a header (team -1: none).
Roster ReadRoster(const std::string& path);
// Writes id,team,name for every id with a team or a name (through a temporary file).
void WriteRoster(const Roster& roster, const std::string& path);
// TRACKS.csv's roster file name: TRACKS.csv.teams.csv.
std::string RosterPathFor(const std::string& tracks_path);
// The teams and names of a tracks file: its roster beside it when there is one, else the tracks'
// own `team` column where it has one (team numbers; other values are no team).
Roster RosterForTracks(const std::string& tracks_path);
// The roster of the tracks just written to `tracks_path`, beside them (RosterPathFor); a roster
// without teams or names removes an earlier run's file there instead, which stats and tracks draw
// would otherwise apply to other people. Returns what was done ("wrote F", "removed F (...)") or
// "" when nothing was there to write or remove.
std::string SaveRosterFor(const std::string& tracks_path, const Roster& roster);

struct EditResult {
  std::vector<TrackRow> rows;
  Roster roster;
  int ids_before = 0, ids_after = 0;
  int merged = 0;            // ids merged into another
  int overlapping_rows = 0;  // frames where merged ids were both present (the surer box kept)
  int renamed = 0, named = 0, teamed = 0;
  int dropped_ids = 0, dropped_rows = 0;
  std::string Summary() const;
};

// Applies the edits in order. Throws fv::Error naming the file and line for an id that is not in
// the tracks (at that point), a rename onto an id in use, or a merge of ids tracked together in
// more than 10 frames.
EditResult ApplyTrackEdits(std::vector<TrackRow> rows, Roster roster, const TrackEdits& edits);

}  // namespace fv::track
