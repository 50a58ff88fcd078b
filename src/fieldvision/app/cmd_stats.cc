// `fieldvision stats`: statistics, heat maps, radar view and an HTML report from TRACKS.csv.
#include <algorithm>
#include <filesystem>
#include <iostream>

#include "fieldvision/app/command.h"
#include "fieldvision/app/input_checks.h"
#include "fieldvision/field/field.h"
#include "fieldvision/stats/stats.h"
#include "fieldvision/track/edits.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

namespace fv::app {
namespace {

struct StatsCli {
  std::string tracks, field, out, zones, teams;
  stats::StatsOptions o;
};

void RunStats(const StatsCli& c) {
  const field::FieldModel field = field::LoadField(c.field);
  const auto rows = track::ReadTracksCsv(c.tracks);
  CheckOneRowPerPlayerFrame(rows, c.tracks);
  stats::StatsOptions o = c.o;
  if (!c.zones.empty()) {
    o.zones = stats::ReadZones(c.zones);
    FV_REQUIRE(!o.zones.empty(), "zones file '{}' has no zones (a JSON array of named polygons)",
               c.zones);
  }
  // --teams, else the roster beside the tracks or their own team column (as the studio).
  const track::Roster roster =
      c.teams.empty() ? track::RosterForTracks(c.tracks) : track::ReadRoster(c.teams);
  o.team_of = roster.team_of;
  o.name_of = roster.name_of;
  o.Check();
  // The library's messages name the rows, not the file they came from.
  const stats::StatsResult r = [&] {
    try {
      return stats::ComputeStats(rows, o);
    } catch (const Error& e) {
      Throw("tracks file '{}': {}", c.tracks, e.what());
    }
  }();
  // The radar video has 10 frames per second of play: refuse spans longer than any match (6 h).
  double t0 = 1e300, t1 = -1e300;
  for (const auto& s : r.tracks) {
    if (s.time_s.empty()) continue;
    t0 = std::min(t0, s.time_s.front());
    t1 = std::max(t1, s.time_s.back());
  }
  FV_REQUIRE(t1 - t0 <= 6 * 3600.0,
             "stats: '{}' spans {:.0f} s of play (over 6 h): check its frame numbers and time_s",
             c.tracks, t1 - t0);
  const stats::ReportFiles f = stats::WriteStatsReport(r, field, o, c.out);
  std::cout << r.Summary() << "\nwrote " << f.files.size() << " files to " << c.out << " (open "
            << c.out << "/index.html)\n";
  for (const auto& n : f.notes) std::cout << "note: " << n << "\n";
}

void Setup(CLI::App& app, int& exit_code) {
  auto c = std::make_shared<StatsCli>();
  CLI::App* cmd = app.add_subcommand(
      "stats", "Statistics for coaches from player tracks: stats.json, heat maps, index.html");
  cmd->add_option("--tracks", c->tracks, "TRACKS.csv from `fieldvision players`")->required();
  cmd->add_option("--field", c->field, "Field: built-in name or JSON file")->required();
  cmd->add_option("--out", c->out, "Output folder")->required();
  cmd->add_option("--fps", c->o.fps,
                  "Override the time in TRACKS.csv (time_s, the video's own): frame f at "
                  "(f - 1) / FPS seconds")
      ->check(FiniteRange(0.01, 10000));
  cmd->add_option("--zones", c->zones,
                  "JSON zones for alerts: [{\"name\": \"box\", \"polygon\": [[x, y], ...]}]");
  cmd->add_option("--teams", c->teams,
                  "id,team[,name] CSV (default: TRACKS.csv.teams.csv if present, as players "
                  "--teams and tracks edit write it, else a team column of TRACKS.csv; team -1: "
                  "none)");
  cmd->add_option("--smooth", c->o.smooth_window_s, "Smoothing window of positions in seconds")
      ->check(FiniteRange(0.01, 60));
  cmd->add_option("--sprint-speed", c->o.sprint_speed_mps, "Sprint threshold in m/s")
      ->check(FiniteRange(0.1, 20));
  cmd->add_option("--noise-floor", c->o.distance_noise_factor,
                  "Distance counts a move once the smoothed position is this many times the "
                  "track's estimated position noise from the last counted one (tracking noise of "
                  "a standing player is no distance; 0: every smoothed step)")
      ->capture_default_str()
      ->check(FiniteRange(0, 10));
  cmd->add_flag("!--no-video", c->o.write_video, "Do not write radar.mp4");
  cmd->callback([c] {
    const auto inputs = util::PathList(c->tracks, c->field, c->zones, c->teams);
    util::CheckOutputPath(c->out, inputs);
    for (const char* name : {"distances.csv", "players.csv", "speed_profiles.csv", "stats.json",
                             "index.html", "radar.png", "radar.mp4", "heatmap_all.png"}) {
      util::CheckOutputPath(c->out + "/" + name, inputs);
    }
    try {
      RunStats(*c);
    } catch (const Error& e) {
      // The statistics' checks of the rows say "the tracks ...": name the file.
      if (!util::StartsWith(e.what(), "the tracks")) throw;
      Throw("{}: {}", c->tracks, e.what());
    }
  });
}

FV_REGISTER_COMMAND(75, "stats", Setup);

}  // namespace
}  // namespace fv::app
