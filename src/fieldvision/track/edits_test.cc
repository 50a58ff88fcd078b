#include "fieldvision/track/edits.h"

#include <fstream>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::track {
namespace {

// Ids over frames 1..n: each id has its own x position.
std::vector<TrackRow> Rows(const std::vector<std::pair<int, std::pair<int, int>>>& spans) {
  std::vector<TrackRow> rows;
  for (const auto& [id, span] : spans) {
    for (int f = span.first; f <= span.second; ++f) {
      rows.push_back({f, id, cv::Rect2d(10.0 * id, 0, 20, 50), 0.5 + 0.01 * id, {}, {}, f / 10.0});
    }
  }
  return rows;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const fv::Error& e) {
    return e.what();
  }
  return "";
}

TEST(TrackEdits, MergeRenameNameTeamDropInOrder) {
  const std::string text = R"([
  {"merge": [3, 7]},
  {"rename": {"3": 10, "5": 11}},
  {"name": {"10": "Anna", "11": "Ben"}},
  {"team": {"10": 0, "11": 1}},
  {"drop": [9]}
])";
  const TrackEdits edits = ParseTrackEdits(text, "e.json");
  ASSERT_EQ(edits.edits.size(), 5u);
  EXPECT_EQ(edits.edits[0].line, 2);
  EXPECT_EQ(edits.edits[4].line, 6);
  // 3 and 7 overlap in frames 8..10 (the surer box, id 7's, is kept there).
  const auto rows = Rows({{3, {1, 10}}, {7, {8, 20}}, {5, {1, 20}}, {9, {1, 3}}});
  Roster roster;
  roster.team_of[7] = 1;  // players --teams: moves to 3 with the merge; the team edit wins
  const EditResult r = ApplyTrackEdits(rows, roster, edits);
  EXPECT_EQ(r.ids_before, 4);
  EXPECT_EQ(r.ids_after, 2);
  EXPECT_EQ(r.merged, 1);
  EXPECT_EQ(r.overlapping_rows, 3);
  EXPECT_EQ(r.dropped_rows, 3);
  std::set<int> ids;
  std::map<int, int> frames_of;
  for (const auto& row : r.rows) {
    ids.insert(row.id);
    frames_of[row.id]++;
    ASSERT_TRUE(row.time_s.has_value());
  }
  EXPECT_EQ(ids, (std::set<int>{10, 11}));
  EXPECT_EQ(frames_of[10], 20);  // frames 1..20, one row each
  for (const auto& row : r.rows) {
    if (row.id == 10 && row.frame >= 8 && row.frame <= 10) EXPECT_NEAR(row.box.x, 70, 1e-9);
  }
  EXPECT_EQ(r.roster.name_of.at(10), "Anna");
  EXPECT_EQ(r.roster.team_of.at(10), 0);
  EXPECT_EQ(r.roster.team_of.at(11), 1);
  // The roster file round-trips.
  const std::string dir = fv::testing::TempDir();
  WriteRoster(r.roster, dir + "/roster.csv");
  const Roster back = ReadRoster(dir + "/roster.csv");
  EXPECT_EQ(back.name_of, r.roster.name_of);
  EXPECT_EQ(back.team_of, r.roster.team_of);
}

// stats and the studio take the same teams: the roster beside the tracks, else their own team
// column (numbers only: "A" is no team), and nothing for a file without a header.
TEST(TrackEdits, RosterForTracksIsTheRosterElseTheTeamColumn) {
  const std::string dir = fv::testing::TempDir();
  const std::string tracks = dir + "/T.csv";
  std::ofstream(tracks) << "frame,id,bb_left,bb_top,bb_width,bb_height,team\n"
                           "1,3,0,0,1,1,1\n1,4,0,0,1,1,A\n1,5,0,0,1,1,\n2,3,0,0,1,1,1\n";
  Roster r = RosterForTracks(tracks);
  EXPECT_EQ(r.team_of, (std::map<int, int>{{3, 1}}));
  std::ofstream(RosterPathFor(tracks)) << "id,team,name\n4,0,Ann\n";
  r = RosterForTracks(tracks);
  EXPECT_EQ(r.team_of, (std::map<int, int>{{4, 0}}));
  EXPECT_EQ(r.name_of.at(4), "Ann");
  const std::string mot = dir + "/gt.txt";
  std::ofstream(mot) << "1,1,0,0,1,1,1,-1,-1,-1\n1,2,0,0,1,1,1,-1,-1,-1\n";
  EXPECT_TRUE(RosterForTracks(mot).team_of.empty());
}

TEST(TrackEdits, ErrorsNameFileAndLine) {
  const auto rows = Rows({{1, {1, 5}}, {2, {1, 5}}});
  const std::string dir = fv::testing::TempDir();
  const std::string path = dir + "/edits.json";
  {
    std::ofstream f(path);
    f << "[\n  {\"team\": {\"1\": 0}},\n  {\"merge\": [1, 99]}\n]\n";
  }
  const std::string unknown = ErrorOf([&] { ApplyTrackEdits(rows, {}, ReadTrackEdits(path)); });
  EXPECT_NE(unknown.find(path + ":3: merge: id 99 is not in the tracks"), std::string::npos)
      << unknown;
  EXPECT_EQ(unknown.find('\n'), std::string::npos);
  // Ids as they are after the edits before: 2 is gone once merged into 1.
  const std::string gone = ErrorOf([&] {
    ApplyTrackEdits(rows, {}, ParseTrackEdits("[{\"merge\": [1, 2]},\n{\"drop\": [2]}]", "e"));
  });
  EXPECT_NE(gone.find("e:2: drop: id 2 is not in the tracks"), std::string::npos) << gone;
  EXPECT_NE(ErrorOf([&] {
              ParseTrackEdits("[{\"merge\": [1, 1]}]", "e");
            }).find("e:1: merge names an id twice"),
            std::string::npos);
  const std::string used = ErrorOf(
      [&] { ApplyTrackEdits(rows, {}, ParseTrackEdits("[{\"rename\": {\"1\": 2}}]", "e")); });
  EXPECT_NE(used.find("e:1: rename: id 2 is already in use"), std::string::npos) << used;
  const std::string together = ErrorOf([&] {
    ApplyTrackEdits(Rows({{1, {1, 30}}, {2, {5, 30}}}), {},
                    ParseTrackEdits("[\n{\"merge\": [1, 2]}]", "e"));
  });
  EXPECT_NE(together.find("e:2: merge: the ids are tracked at the same time in 26 frames (from "
                          "frame 5)"),
            std::string::npos)
      << together;
  const std::string json =
      ErrorOf([&] { ParseTrackEdits("[\n{\"merge\": [1, 2]},\n{\"drop\": [2}\n]", "e"); });
  EXPECT_NE(json.find("e:3: not valid JSON"), std::string::npos) << json;
  EXPECT_EQ(json.find('\n'), std::string::npos);
  const std::string op = ErrorOf([&] { ParseTrackEdits("[\n\n {\"split\": [1]}]", "e"); });
  EXPECT_NE(op.find("e:3: unknown edit 'split'"), std::string::npos) << op;
  const std::string line_break = ErrorOf([&] {
    ApplyTrackEdits(rows, {}, ParseTrackEdits("[{\"name\": {\"1\": \"Ann\\nB\"}}]", "e"));
  });
  EXPECT_NE(line_break.find("'Ann?B' must not contain commas, quotes or line breaks"),
            std::string::npos)
      << line_break;
  EXPECT_EQ(line_break.find('\n'), std::string::npos);
  const std::string one = ErrorOf([&] { ParseTrackEdits("[{\"merge\": [1]}]", "e"); });
  EXPECT_NE(one.find("e:1: merge needs two or more ids"), std::string::npos) << one;
  EXPECT_NE(ErrorOf([&] { ReadTrackEdits(dir + "/none.json"); }).find("none.json"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf([&] { ParseTrackEdits("{\"merge\": [1, 2]}", "e"); }).find("e:1: expected an array"),
      std::string::npos);
}

}  // namespace
}  // namespace fv::track
