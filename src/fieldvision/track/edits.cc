#include "fieldvision/track/edits.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

namespace fv::track {
namespace {

using json = nlohmann::json;

// Frames in which ids merged into one may both be tracked (a hand-over between two tracklets).
constexpr int kMaxMergeOverlapFrames = 10;

int LineOfByte(const std::string& text, size_t byte) {
  byte = std::min(byte, text.size());
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + byte, '\n'));
}

// Lines where the elements of the top-level array start (skipping strings and nesting).
std::vector<int> TopLevelElementLines(const std::string& text) {
  std::vector<int> lines;
  int depth = 0, line = 1;
  bool expect_element = false;
  util::ScanJsonText(text, [&](char c, bool in_string) {
    if (c == '\n') ++line;
    if (in_string || std::isspace(static_cast<unsigned char>(c))) return true;
    if (expect_element && depth == 1 && c != ']') {
      lines.push_back(line);
      expect_element = false;
    }
    if (c == '[' || c == '{') {
      ++depth;
      if (depth == 1 && c == '[') expect_element = true;
    } else if (c == ']' || c == '}') {
      --depth;
    } else if (c == ',' && depth == 1) {
      expect_element = true;
    }
    return true;
  });
  return lines;
}

int IdFrom(const json& v, const std::string& where) {
  if (v.is_number_integer()) return v.get<int>();
  if (v.is_string()) {
    return static_cast<int>(util::ParseInt(util::Trim(v.get<std::string>()), where + " id"));
  }
  Throw("{}: expected an id (a whole number), got {}", where, v.dump());
}

std::vector<int> IdList(const json& v, const std::string& where) {
  FV_REQUIRE(v.is_array(), "{}: expected a list of ids such as [3, 17]", where);
  std::vector<int> ids;
  for (const auto& e : v) ids.push_back(IdFrom(e, where));
  return ids;
}

}  // namespace

TrackEdits ParseTrackEdits(const std::string& text, const std::string& path) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    Throw("{}:{}: not valid JSON (byte {})", path, LineOfByte(text, e.byte > 0 ? e.byte - 1 : 0),
          e.byte);
  }
  FV_REQUIRE(j.is_array(),
             "{}:1: expected an array of edits such as [{{\"merge\": [3, 17]}}, {{\"team\": "
             "{{\"3\": 0}}}}]",
             path);
  const std::vector<int> lines = TopLevelElementLines(text);
  TrackEdits out;
  out.path = path;
  for (size_t i = 0; i < j.size(); ++i) {
    TrackEdit e;
    e.line = i < lines.size() ? lines[i] : 1;
    const std::string where = fmt::format("{}:{}", path, e.line);
    const json& v = j[i];
    FV_REQUIRE(v.is_object() && v.size() == 1,
               "{}: each edit is an object with one of merge, rename, name, team, drop", where);
    const std::string op = v.begin().key();
    const json& arg = v.begin().value();
    if (op == "merge" || op == "drop") {
      e.kind = op == "merge" ? TrackEdit::Kind::kMerge : TrackEdit::Kind::kDrop;
      e.ids = IdList(arg, fmt::format("{}: {}", where, op));
      FV_REQUIRE(op != "merge" || e.ids.size() >= 2, "{}: merge needs two or more ids", where);
      FV_REQUIRE(std::set<int>(e.ids.begin(), e.ids.end()).size() == e.ids.size(),
                 "{}: {} names an id twice", where, op);
      FV_REQUIRE(!e.ids.empty(), "{}: {} needs one or more ids", where, op);
    } else if (op == "rename" || op == "team") {
      e.kind = op == "rename" ? TrackEdit::Kind::kRename : TrackEdit::Kind::kTeam;
      FV_REQUIRE(arg.is_object() && !arg.empty(), "{}: {} expects {{\"id\": {}, ...}}", where, op,
                 op == "rename" ? "new id" : "team");
      for (const auto& [k, val] : arg.items()) {
        FV_REQUIRE(val.is_number_integer(), "{}: {}: the value for id {} must be a whole number",
                   where, op, k);
        e.to[IdFrom(json(k), fmt::format("{}: {}", where, op))] = val.get<int>();
      }
    } else if (op == "name") {
      e.kind = TrackEdit::Kind::kName;
      FV_REQUIRE(arg.is_object() && !arg.empty(), "{}: name expects {{\"id\": \"name\", ...}}",
                 where);
      for (const auto& [k, val] : arg.items()) {
        FV_REQUIRE(val.is_string(), "{}: name: the name of id {} must be a string", where, k);
        const std::string n = val.get<std::string>();
        FV_REQUIRE(n.find_first_of(",\n\r\"") == std::string::npos,
                   "{}: name: '{}' must not contain commas, quotes or line breaks", where,
                   util::Shown(n));
        e.names[IdFrom(json(k), where + ": name")] = n;
      }
    } else {
      Throw("{}: unknown edit '{}' (known: merge, rename, name, team, drop)", where, op);
    }
    out.edits.push_back(std::move(e));
  }
  return out;
}

TrackEdits ReadTrackEdits(const std::string& path) {
  std::ifstream in(path);
  FV_REQUIRE(in.good(), "cannot open edits file '{}'", path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseTrackEdits(ss.str(), path);
}

Roster ReadRoster(const std::string& path) {
  const util::CsvTable t = util::CsvTable::Read(path);
  t.Require({"id", "team"});
  Roster r;
  for (size_t i = 0; i < t.rows(); ++i) {
    const int id = static_cast<int>(t.GetInt(i, "id"));
    const int team = static_cast<int>(t.GetInt(i, "team"));
    if (team >= 0) r.team_of[id] = team;
    const std::string name = t.Has("name") ? util::Trim(t.Get(i, "name")) : std::string();
    if (!name.empty()) r.name_of[id] = name;
  }
  return r;
}

Roster RosterForTracks(const std::string& tracks_path) {
  const std::string beside = RosterPathFor(tracks_path);
  if (std::filesystem::is_regular_file(beside)) return ReadRoster(beside);
  Roster r;
  std::optional<util::CsvTable> read;
  try {
    read = util::CsvTable::Read(tracks_path);
  } catch (const Error&) {
    return r;  // a MOTChallenge file without a header: no team column
  }
  const util::CsvTable& t = *read;
  if (!t.Has("team") || !t.Has("id")) return r;
  for (size_t i = 0; i < t.rows(); ++i) {
    long long team = -1;
    try {
      team = util::ParseInt(t.Get(i, "team"), t.Where(i));
    } catch (const Error&) {
      continue;  // empty or not a team number ("A"): no team
    }
    if (team >= 0 && team < 1000) r.team_of.emplace(static_cast<int>(t.GetInt(i, "id")), team);
  }
  return r;
}

void WriteRoster(const Roster& roster, const std::string& path) {
  std::set<int> ids;
  for (const auto& [id, t] : roster.team_of) ids.insert(id);
  for (const auto& [id, n] : roster.name_of) ids.insert(id);
  util::AtomicWrite(
      path,
      [&](const std::string& tmp) {
        util::CsvWriter w(tmp, {"id", "team", "name"});
        for (int id : ids) {
          const auto t = roster.team_of.find(id);
          const auto n = roster.name_of.find(id);
          w << id << (t == roster.team_of.end() ? -1 : t->second)
            << (n == roster.name_of.end() ? std::string() : n->second);
          w.EndRow();
        }
        w.Close();
      },
      "roster");
}

std::string RosterPathFor(const std::string& tracks_path) { return tracks_path + ".teams.csv"; }

std::string SaveRosterFor(const std::string& tracks_path, const Roster& roster) {
  const std::string path = RosterPathFor(tracks_path);
  if (!roster.team_of.empty() || !roster.name_of.empty()) {
    WriteRoster(roster, path);
    return fmt::format("wrote {} (teams and names, read by stats and tracks draw)", path);
  }
  if (!util::RemoveEarlierFile(path, "teams file")) return "";
  return fmt::format("removed {} (an earlier run's teams and names: these tracks have none)", path);
}

std::string EditResult::Summary() const {
  return fmt::format(
      "{} ids -> {}: {} merged ({} frames with both: the surer box kept), {} renamed, {} named, "
      "{} given a team, {} dropped ({} rows)",
      ids_before, ids_after, merged, overlapping_rows, renamed, named, teamed, dropped_ids,
      dropped_rows);
}

namespace {

// The state of ApplyTrackEdits between edits: the rows, roster and ids as they are so far.
class TrackEditor {
 public:
  TrackEditor(std::vector<TrackRow> rows, Roster roster, const std::string& path)
      : rows_(std::move(rows)), roster_(std::move(roster)), path_(path) {
    for (const auto& r : rows_) ids_.insert(r.id);
    res_.ids_before = static_cast<int>(ids_.size());
  }

  void Apply(const TrackEdit& e) {
    switch (e.kind) {
      case TrackEdit::Kind::kMerge:
        Merge(e);
        break;
      case TrackEdit::Kind::kRename:
        Rename(e);
        break;
      case TrackEdit::Kind::kName:
        for (const auto& [id, n] : e.names) {
          RequireKnown(id, e, "name");
          roster_.name_of[id] = n;
        }
        res_.named += static_cast<int>(e.names.size());
        break;
      case TrackEdit::Kind::kTeam:
        Team(e);
        break;
      case TrackEdit::Kind::kDrop:
        Drop(e);
        break;
    }
  }

  EditResult Finish() && {
    SortRows();
    res_.ids_after = static_cast<int>(ids_.size());
    res_.rows = std::move(rows_);
    res_.roster = std::move(roster_);
    return std::move(res_);
  }

 private:
  void RequireKnown(int id, const TrackEdit& e, const char* op) const {
    FV_REQUIRE(ids_.count(id), "{}:{}: {}: id {} is not in the tracks{}", path_, e.line, op, id,
               ids_.empty() ? std::string()
                            : fmt::format(" (ids {}..{}, {} in all)", *ids_.begin(), *ids_.rbegin(),
                                          ids_.size()));
  }

  void SortRows() {
    std::stable_sort(rows_.begin(), rows_.end(), [](const TrackRow& a, const TrackRow& b) {
      return a.frame != b.frame ? a.frame < b.frame : a.id < b.id;
    });
  }

  // Moves roster entries from one id to another (the target's own entries win).
  void MoveRoster(int from, int to) {
    if (roster_.team_of.count(from) && !roster_.team_of.count(to)) {
      roster_.team_of[to] = roster_.team_of[from];
    }
    if (roster_.name_of.count(from) && !roster_.name_of.count(to)) {
      roster_.name_of[to] = roster_.name_of[from];
    }
    roster_.team_of.erase(from);
    roster_.name_of.erase(from);
  }

  void Merge(const TrackEdit& e) {
    const int keep = e.ids.front();
    std::set<int> from;
    for (int id : e.ids) {
      RequireKnown(id, e, "merge");
      if (id != keep) from.insert(id);
    }
    for (auto& r : rows_) {
      if (from.count(r.id)) r.id = keep;
    }
    // One row per frame: where both were present, keep the more confident box.
    SortRows();
    std::vector<TrackRow> out;
    out.reserve(rows_.size());
    int overlap = 0, first_overlap = 0;
    for (const auto& r : rows_) {
      if (!out.empty() && out.back().frame == r.frame && out.back().id == r.id) {
        if (overlap++ == 0) first_overlap = r.frame;
        if (r.conf > out.back().conf) out.back() = r;
        continue;
      }
      out.push_back(r);
    }
    // Two ids seen together for long are two people, not one tracked in pieces.
    FV_REQUIRE(overlap <= kMaxMergeOverlapFrames,
               "{}:{}: merge: the ids are tracked at the same time in {} frames (from frame "
               "{}): two people, not one (at most {} frames may overlap)",
               path_, e.line, overlap, first_overlap, kMaxMergeOverlapFrames);
    res_.overlapping_rows += overlap;
    rows_ = std::move(out);
    for (int id : from) {
      MoveRoster(id, keep);
      ids_.erase(id);
    }
    res_.merged += static_cast<int>(from.size());
  }

  void Rename(const TrackEdit& e) {
    for (const auto& [from, to] : e.to) RequireKnown(from, e, "rename");
    std::set<int> after = ids_;
    for (const auto& [from, to] : e.to) after.erase(from);
    for (const auto& [from, to] : e.to) {
      FV_REQUIRE(!after.count(to),
                 "{}:{}: rename: id {} is already in use (merge {} into it instead)", path_, e.line,
                 to, from);
      after.insert(to);
    }
    for (auto& r : rows_) {
      const auto it = e.to.find(r.id);
      if (it != e.to.end()) r.id = it->second;
    }
    Roster moved;
    for (const auto& [id, t] : roster_.team_of) {
      const auto it = e.to.find(id);
      moved.team_of[it == e.to.end() ? id : it->second] = t;
    }
    for (const auto& [id, n] : roster_.name_of) {
      const auto it = e.to.find(id);
      moved.name_of[it == e.to.end() ? id : it->second] = n;
    }
    roster_ = std::move(moved);
    ids_ = std::move(after);
    res_.renamed += static_cast<int>(e.to.size());
  }

  void Team(const TrackEdit& e) {
    for (const auto& [id, team] : e.to) {
      RequireKnown(id, e, "team");
      FV_REQUIRE(team >= -1 && team <= 99, "{}:{}: team: {} for id {} is not -1..99", path_, e.line,
                 team, id);
      if (team < 0) {
        roster_.team_of.erase(id);
      } else {
        roster_.team_of[id] = team;
      }
    }
    res_.teamed += static_cast<int>(e.to.size());
  }

  void Drop(const TrackEdit& e) {
    const std::set<int> drop(e.ids.begin(), e.ids.end());
    for (int id : drop) RequireKnown(id, e, "drop");
    const size_t before = rows_.size();
    std::erase_if(rows_, [&](const TrackRow& r) { return drop.count(r.id) > 0; });
    res_.dropped_rows += static_cast<int>(before - rows_.size());
    for (int id : drop) {
      ids_.erase(id);
      roster_.team_of.erase(id);
      roster_.name_of.erase(id);
    }
    res_.dropped_ids += static_cast<int>(drop.size());
  }

  std::vector<TrackRow> rows_;
  Roster roster_;
  const std::string& path_;
  std::set<int> ids_;
  EditResult res_;
};

}  // namespace

EditResult ApplyTrackEdits(std::vector<TrackRow> rows, Roster roster, const TrackEdits& edits) {
  TrackEditor editor(std::move(rows), std::move(roster), edits.path);
  for (const TrackEdit& e : edits.edits) editor.Apply(e);
  return std::move(editor).Finish();
}

}  // namespace fv::track
