// `fieldvision tracks edit`: fix identities in TRACKS.csv by hand (merge, rename, name, team,
// drop) from a small JSON file, before `stats` (track/edits.h).
#include <filesystem>
#include <iostream>

#include "fieldvision/app/command.h"
#include "fieldvision/track/edits.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/util/error.h"

namespace fv::app {
namespace {

struct TracksEditCli {
  std::string tracks, edits, out, roster_in;
};

void RunTracksEdit(const TracksEditCli& c) {
  const auto rows = track::ReadTracksCsv(c.tracks);
  const track::TrackEdits edits = track::ReadTrackEdits(c.edits);
  std::string roster_in = c.roster_in;
  if (roster_in.empty() && std::filesystem::exists(track::RosterPathFor(c.tracks))) {
    roster_in = track::RosterPathFor(c.tracks);
  }
  const track::Roster roster = roster_in.empty() ? track::Roster{} : track::ReadRoster(roster_in);
  const track::EditResult r = track::ApplyTrackEdits(rows, roster, edits);
  track::WriteTracksCsv(r.rows, c.out);
  std::cout << r.Summary() << "\nwrote " << c.out;
  if (!r.roster.team_of.empty() || !r.roster.name_of.empty()) {
    track::WriteRoster(r.roster, track::RosterPathFor(c.out));
    std::cout << " and " << track::RosterPathFor(c.out) << " (teams and names, read by stats)";
  }
  std::cout << "\n";
}

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "tracks", "Fix player tracks by hand");
  auto c = std::make_shared<TracksEditCli>();
  CLI::App* cmd = group->add_subcommand(
      "edit",
      "Apply identity edits to TRACKS.csv (merge ids, rename to shirt numbers, names, teams, drop "
      "ids); run stats on the result");
  cmd->add_option("--tracks", c->tracks, "TRACKS.csv from `fieldvision players`")->required();
  cmd->add_option("--edits", c->edits,
                  "JSON array of edits, applied in order: {\"merge\": [3, 17]}, "
                  "{\"rename\": {\"3\": 10}}, {\"name\": {\"10\": \"Anna\"}}, "
                  "{\"team\": {\"10\": 0}}, {\"drop\": [5]}")
      ->required();
  cmd->add_option("--out", c->out,
                  "Edited TRACKS.csv (teams and names go to OUT.teams.csv beside it)")
      ->required();
  cmd->add_option("--roster", c->roster_in,
                  "id,team[,name] CSV to start from (default: TRACKS.csv.teams.csv if present)");
  cmd->callback([c] { RunTracksEdit(*c); });
}

FV_REGISTER_COMMAND(72, "tracks edit", Setup);

}  // namespace
}  // namespace fv::app
