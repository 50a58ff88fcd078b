#include "fieldvision/stats/stats.h"

#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "fieldvision/field/field_draw.h"
#include "fieldvision/io/video_writer.h"
#include "fieldvision/track/overlay.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::stats {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// A player walking 1.5 m/s along +x for 10 s, then sprinting 7 m/s for 3 s, then standing 3 s,
// with Gaussian position noise; 25 frames/s.
std::vector<track::TrackRow> Runner(util::Rng& rng, int id, double y, double noise_m,
                                    double* distance) {
  std::vector<track::TrackRow> rows;
  const double fps = 25;
  double x = -20;
  *distance = 0;
  for (int f = 0; f < 16 * 25; ++f) {
    const double t = f / fps;
    const double v = t < 10 ? 1.5 : (t < 13 ? 7.0 : 0.0);
    if (f > 0) {
      x += v / fps;
      *distance += v / fps;
    }
    track::TrackRow r;
    r.frame = f + 1;  // MOTChallenge numbering
    r.time_s = t;
    r.id = id;
    r.box = cv::Rect2d(0, 0, 10, 20);
    r.x_m = x + rng.Normal(0, noise_m);
    r.y_m = y + rng.Normal(0, noise_m);
    rows.push_back(r);
  }
  return rows;
}

TEST(Stats, DistanceSpeedAndSprintsFromNoisyPositions) {
  fv::testing::SeededRng rng(21);
  double truth = 0;
  const auto rows = Runner(rng, 4, 0.0, 0.05, &truth);
  StatsOptions o;
  o.zones = {{"right", {{10, -5}, {40, -5}, {40, 5}, {10, 5}}}};
  const StatsResult r = ComputeStats(rows, o);
  ASSERT_EQ(r.players.size(), 1u);
  const PlayerStats& p = r.players[0];
  // Raw noisy positions would add about 400 * 0.05 * sqrt(pi)... metres; smoothed stays close.
  double raw = 0;
  for (size_t i = 1; i < rows.size(); ++i) {
    raw += std::hypot(*rows[i].x_m - *rows[i - 1].x_m, *rows[i].y_m - *rows[i - 1].y_m);
  }
  EXPECT_GT(raw, truth * 1.3);
  EXPECT_NEAR(p.distance_m, truth, 0.05 * truth) << "raw " << raw;
  EXPECT_NEAR(p.top_speed_mps, 7.0, 0.7);
  EXPECT_EQ(p.sprints, 1);
  EXPECT_NEAR(p.mean_speed_mps, truth / 16.0, 0.3);
  // x passes 10 m at t = 30 / 7 s into the sprint: 10 + (10 - (-20 + 15)) / 7.
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].id, 4);
  EXPECT_NEAR(r.events[0].enter_s, 10.0 + 15.0 / 7.0, 0.2);
  EXPECT_NEAR(p.zone_time_s.at("right"), 16.0 - r.events[0].enter_s, 0.2);
  // Speed bands add up to the time tracked.
  double bands = 0;
  for (double b : p.band_time_s) bands += b;
  EXPECT_NEAR(bands, p.last_s - p.first_s, 1e-6);
}

// A jogger at 3 m/s along x for 60 s (180 m), seen at `fps`, every `every`-th frame kept, with
// Gaussian position noise.
std::vector<track::TrackRow> Jogger(util::Rng& rng, double fps, int every, double noise_m) {
  std::vector<track::TrackRow> rows;
  for (int f = 0; f <= 60 * fps; f += every) {
    track::TrackRow r;
    r.frame = f + 1;
    r.time_s = f / fps;
    r.id = 1;
    r.box = cv::Rect2d(0, 0, 10, 20);
    r.x_m = -30 + 3.0 * f / fps + rng.Normal(0, noise_m);
    r.y_m = rng.Normal(0, noise_m);
    rows.push_back(r);
  }
  return rows;
}

// The numbers do not depend on how often a player is sampled: positions twice a second (frames
// 0.52 s apart were each a gap: 0 m, no speed) and a high frame rate with 0.2 m of noise (steps
// split as jumps: 144-151 m at 60 fps, a top speed of 12 m/s at 100 fps) give the jogger's 180 m.
TEST(Stats, SparseOrFastNoisySamplesGiveTheSameDistanceAndSpeed) {
  fv::testing::SeededRng rng(23);
  struct Case {
    double fps;
    int every;
    double noise_m;
  };
  for (const Case c : {Case{25, 13, 0.0}, Case{25, 1, 0.2}, Case{60, 1, 0.2}, Case{100, 1, 0.2}}) {
    SCOPED_TRACE(fmt::format("{} fps, every {} frames, noise {} m", c.fps, c.every, c.noise_m));
    const StatsResult r = ComputeStats(Jogger(rng, c.fps, c.every, c.noise_m), StatsOptions());
    ASSERT_EQ(r.players.size(), 1u);
    EXPECT_NEAR(r.players[0].distance_m, 180.0, 0.06 * 180.0);
    EXPECT_NEAR(r.players[0].top_speed_mps, 3.0, 0.3);
    double bands = 0;
    for (double b : r.players[0].band_time_s) bands += b;
    EXPECT_NEAR(bands, 60.0, 0.6);
    EXPECT_NEAR(r.players[0].tracked_s, 60.0, 0.6);
  }
  // A gap of 2 s is not followed: tracked_s says so (from_s..to_s still spans it).
  std::vector<track::TrackRow> holed = Jogger(rng, 25, 1, 0.0);
  std::erase_if(
      holed, [](const track::TrackRow& row) { return *row.time_s > 20.0 && *row.time_s < 22.0; });
  const StatsResult r = ComputeStats(holed, StatsOptions());
  EXPECT_NEAR(r.players[0].tracked_s, 58.0, 0.1);
  EXPECT_NEAR(r.players[0].last_s - r.players[0].first_s, 60.0, 1e-9);
}

// A fragment is as long as it was followed, not as the span of its rows: one row, then four
// rows 3.3 s later (PETS id 17: "2.05 m/s top speed" from 0.3 s of data), and an id seen once,
// are left out and named; the jogger stays.
TEST(Stats, FragmentsFollowedForUnderASecondAreLeftOutAndNamed) {
  fv::testing::SeededRng rng(29);
  std::vector<track::TrackRow> rows = Jogger(rng, 10, 1, 0.0);
  auto add = [&](int id, double t, double x) {
    track::TrackRow r;
    r.frame = static_cast<int>(std::lround(10 * t)) + 1;
    r.time_s = t;
    r.id = id;
    r.box = cv::Rect2d(0, 0, 10, 20);
    r.x_m = x;
    r.y_m = 5.0;
    rows.push_back(r);
  };
  add(17, 46.4, 0.0);
  for (int k = 0; k < 4; ++k) add(17, 49.7 + 0.1 * k, 7.0 + 0.2 * k);
  add(98, 12.0, 3.0);
  // A few scattered rows are no slow sampling: two 10 s apart, five 5 s apart 100 m to and fro
  // (they were bridged: 30 m and 200 m).
  add(20, 2.0, 0.0);
  add(20, 12.0, 30.0);
  for (int k = 0; k < 5; ++k) add(21, 5.0 * k, k % 2 ? 50.0 : -50.0);
  const StatsResult r = ComputeStats(rows, StatsOptions());
  ASSERT_EQ(r.players.size(), 1u);
  EXPECT_EQ(r.players[0].id, 1);
  EXPECT_EQ(r.left_out, (std::vector<int>{17, 20, 21, 98}));
  EXPECT_NE(r.Summary().find("4 ids left out, each followed for under 1 s in all: 17, 20, 21, 98"),
            std::string::npos)
      << r.Summary();
}

// Tracking noise is not running: a player standing for a minute with 10 cm position noise at
// 25 frames/s (stream timestamps jittered by up to 6 ms), and one walking 6 m in that minute,
// with the same noise.
TEST(Stats, NoiseOfAStandingPlayerIsNoDistance) {
  fv::testing::SeededRng rng(22);
  std::vector<track::TrackRow> rows;
  for (int f = 0; f < 60 * 25; ++f) {
    const double jitter_s = rng.Uniform(-0.006, 0.006);
    for (int id : {1, 2}) {
      track::TrackRow r;
      r.frame = f + 1;
      r.time_s = f / 25.0 + jitter_s;
      r.id = id;
      r.box = cv::Rect2d(0, 0, 10, 20);
      r.x_m = (id == 1 ? 3.0 : -20.0 + 0.1 * *r.time_s) + rng.Normal(0, 0.1);
      r.y_m = 5.0 * id + rng.Normal(0, 0.1);
      rows.push_back(r);
    }
  }
  const StatsResult r = ComputeStats(rows, StatsOptions());
  ASSERT_EQ(r.players.size(), 2u);
  for (const PlayerStats& p : r.players) EXPECT_NEAR(p.position_noise_m, 0.1, 0.01) << p.id;
  EXPECT_LT(r.players[0].distance_m, 1.0);
  EXPECT_NEAR(r.players[1].distance_m, 6.0, 1.0);
  EXPECT_NEAR(r.players[1].mean_speed_mps, 0.1, 0.02);
  // Every smoothed step counted, as before: 18 m standing still.
  StatsOptions all_steps;
  all_steps.distance_noise_factor = 0;
  EXPECT_GT(ComputeStats(rows, all_steps).players[0].distance_m, 10.0);
}

TEST(Stats, PairDistancesAndReport) {
  fv::testing::SeededRng rng(22);
  double d1 = 0, d2 = 0;
  auto rows = Runner(rng, 1, -3.0, 0.02, &d1);
  const auto other = Runner(rng, 2, 3.0, 0.02, &d2);
  rows.insert(rows.end(), other.begin(), other.end());
  StatsOptions o;
  o.team_of = {{1, 0}, {2, 1}};
  o.write_video = true;
  const StatsResult r = ComputeStats(rows, o);
  ASSERT_FALSE(r.pair_distances.empty());
  for (const auto& [t, a, b, d] : r.pair_distances) EXPECT_NEAR(d, 6.0, 0.2) << "t " << t;
  const std::string dir = fv::testing::TempDir() + "/report";
  const field::FieldModel field = field::BuiltinField("futsal");
  const ReportFiles files = WriteStatsReport(r, field, o, dir);
  for (const char* f :
       {"stats.json", "index.html", "heatmap_all.png", "heatmap_team0.png", "heatmap_team1.png",
        "heatmap_player1.png", "radar.png", "distances.csv", "players.csv", "speed_profiles.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + f)) << f;
  }
  // The radar video browsers play, where OpenCV can write H.264; else a note says why not.
  if (io::H264Available()) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/radar.mp4"));
  } else {
    EXPECT_EQ(files.notes.size(), 1u);
  }
  // players.csv has one row per player with the table's numbers.
  const util::CsvTable players = util::CsvTable::Read(dir + "/players.csv");
  ASSERT_EQ(players.rows(), 2u);
  EXPECT_NEAR(players.GetDouble(0, "distance_m"), r.players[0].distance_m, 0.01);
  // The hottest place of player 1's map is where it stood longest: the end of its path.
  const cv::Mat heat = cv::imread(dir + "/heatmap_player1.png");
  ASSERT_FALSE(heat.empty());
  // The report's view: the field with a 2 m margin (every position on it), framed with axes.
  const field::TopView view =
      field::TopView::ForField(field, o.image_width_px - field::kTopViewFrameWidthPx, 2.0);
  const cv::Point2d frame(field::kTopViewFrameLeftPx, field::kTopViewFrameTopPx);
  const cv::Point2d end = view.ToPixel({*rows[16 * 25 - 1].x_m, -3.0}) + frame;
  const cv::Point2d start = view.ToPixel({-12.0, -3.0}) + frame;  // walked through, off the lines
  // JET maps the top of the scale to dark red: more red than blue at the end, less red where it
  // only walked through.
  const cv::Vec3b e = heat.at<cv::Vec3b>(cv::Point(end));
  const cv::Vec3b s = heat.at<cv::Vec3b>(cv::Point(start));
  EXPECT_GT(e[2], e[0] + 50) << e;
  EXPECT_GT(int(e[2]) - int(e[1]), int(s[2]) - int(s[1])) << e << s;
  // The colour scale is drawn to the right of the field.
  EXPECT_GT(heat.cols, view.size.width + 50);
  std::ifstream html(dir + "/index.html");
  const std::string text((std::istreambuf_iterator<char>(html)), {});
  EXPECT_NE(text.find("heatmap_player2.png"), std::string::npos);
  EXPECT_NE(text.find("radar.png"), std::string::npos);
  EXPECT_NE(text.find("<svg"), std::string::npos);  // speed over time
  EXPECT_NE(text.find("players.csv"), std::string::npos);
}

// Positions far beyond the drawn field (tracks of another field, a wrong camera) are said in a
// note, not dropped silently; a track sampled every 10 s fills its heat map with its whole time.
TEST(Stats, PositionsBeyondThePictureAreNotedAndSparseSamplesCount) {
  std::vector<track::TrackRow> rows;
  for (int i = 0; i < 30; ++i) {
    track::TrackRow a;
    a.frame = i + 1;
    a.id = 1;
    a.box = cv::Rect2d(0, 0, 10, 20);
    a.x_m = -5.0 + 0.01 * i;
    a.y_m = 2.0;
    a.time_s = 4.0 * i;  // one position every 4 s
    rows.push_back(a);
    track::TrackRow b = a;
    b.id = 2;
    b.y_m = 60.0;  // far beyond a futsal field
    rows.push_back(b);
  }
  StatsOptions o;
  o.write_video = false;
  const StatsResult r = ComputeStats(rows, o);
  const std::string dir = fv::testing::TempDir() + "/beyond";
  const ReportFiles files = WriteStatsReport(r, field::BuiltinField("futsal"), o, dir);
  ASSERT_EQ(files.notes.size(), 1u);
  EXPECT_NE(files.notes[0].find("30 of 60 positions (1 players) lie more than"), std::string::npos)
      << files.notes[0];
  // Player 2's map says it is empty instead of drawing a scale from 0 to 0.
  const cv::Mat empty = cv::imread(dir + "/heatmap_player2.png");
  ASSERT_FALSE(empty.empty());
  // Player 1's 30 positions 4 s apart stand for 120 s on its map (a fixed 0.5 s cap: 15 s).
  const SmoothTrack* one = nullptr;
  for (const auto& t : r.tracks) {
    if (t.id == 1) one = &t;
  }
  ASSERT_NE(one, nullptr);
  const field::TopView view = field::TopView::ForField(field::BuiltinField("futsal"), 800, 2.0);
  const cv::Mat density = TimeSpentPerSquareMetre({one}, view, o);
  EXPECT_NEAR(cv::sum(density)[0] / (view.px_per_m * view.px_per_m), 120.0, 1.2);
}

// The time comes from TRACKS.csv's time_s (here 10 frames/s, the rate of the video), --fps
// overrides it, and tracks without time_s and without --fps are an error that says what to do.
TEST(Stats, TimeFromTracksAndRateOverride) {
  fv::testing::SeededRng rng(23);
  std::vector<track::TrackRow> rows;
  const double v = 1.5, fps = 10;  // walking 1.5 m/s filmed at 10 frames/s
  for (int f = 0; f < 100; ++f) {
    track::TrackRow r;
    r.frame = f + 1;
    r.id = 3;
    r.time_s = f / fps;
    r.x_m = v * f / fps + rng.Normal(0, 0.03);
    r.y_m = rng.Normal(0, 0.03);
    rows.push_back(r);
  }
  const StatsResult r = ComputeStats(rows, StatsOptions{});
  EXPECT_NEAR(r.fps, fps, 1e-6);
  EXPECT_NE(r.Summary().find("10.00 frames/s"), std::string::npos) << r.Summary();
  ASSERT_EQ(r.players.size(), 1u);
  // The top speed is a 1-s mean of the smoothed speed over windows the track covers whole: 3 cm
  // of position noise does not inflate it much (over seeds 1-100 at most 0.09 m/s, mean 0.03;
  // with quadratic slopes at the track's ends and windows cut by them, 22 seeds were over 0.1
  // m/s, up to 0.22).
  EXPECT_NEAR(r.players[0].top_speed_mps, v, 0.12);
  EXPECT_NEAR(r.duration_s, 9.9, 1e-6);
  // --fps 25 would make the same frames 2.5 times faster.
  StatsOptions o;
  o.fps = 25;
  const StatsResult fast = ComputeStats(rows, o);
  EXPECT_NEAR(fast.players[0].top_speed_mps, v * 2.5, 0.6);
  EXPECT_NE(fast.Summary().find("--fps 25"), std::string::npos) << fast.Summary();
  // Times in milliseconds, positions in millimetres: named, not 0.01 frames/s and no speed.
  std::vector<track::TrackRow> ms = rows, mm = rows;
  for (auto& row : ms) *row.time_s *= 1000;
  EXPECT_THAT([&] { ComputeStats(ms, StatsOptions{}); },
              ThrowsMessage<fv::Error>(HasSubstr("are they seconds, not milliseconds?")));
  for (auto& row : mm) {
    *row.x_m *= 1000;
    *row.y_m *= 1000;
  }
  EXPECT_THAT([&] { ComputeStats(mm, StatsOptions{}); },
              ThrowsMessage<fv::Error>(HasSubstr("are x_m, y_m metres")));
  for (auto& row : rows) row.time_s.reset();
  EXPECT_THAT([&] { ComputeStats(rows, StatsOptions{}); },
              ThrowsMessage<fv::Error>(HasSubstr("--fps")));
  EXPECT_NO_THROW(ComputeStats(rows, o));
}

TEST(Stats, BadInputs) {
  StatsOptions o;
  o.fps = -1;
  EXPECT_THROW(o.Check(), fv::Error);
  std::vector<track::TrackRow> no_positions = {{0, 1, cv::Rect2d(0, 0, 1, 1), 1, {}, {}}};
  EXPECT_THAT([&] { ComputeStats(no_positions, StatsOptions{}); },
              ThrowsMessage<fv::Error>(HasSubstr("x_m")));
  // No rows at all is said as such (it read "run players with a calibrated camera").
  EXPECT_THAT([&] { ComputeStats({}, StatsOptions{}); },
              ThrowsMessage<fv::Error>(HasSubstr("no rows")));
  const std::string dir = fv::testing::TempDir();
  {
    std::ofstream f(dir + "/zones.json");
    f << "[{\"name\": \"a\", \"polygon\": [[0, 0], [1, 0]]}]";
  }
  EXPECT_THROW(ReadZones(dir + "/zones.json"), fv::Error);
  EXPECT_THROW(ReadZones(dir + "/none.json"), fv::Error);
  EXPECT_TRUE(InPolygon({{0, 0}, {2, 0}, {2, 2}, {0, 2}}, {1, 1}));
  EXPECT_FALSE(InPolygon({{0, 0}, {2, 0}, {2, 2}, {0, 2}}, {3, 1}));
}

// A hand-made smoothed track: 1 m/s for 4 s, then 6 m/s for 2 s (one segment), 10 samples/s.
SmoothTrack StepTrack(int id) {
  SmoothTrack s;
  s.id = id;
  double x = 0;
  for (int k = 0; k <= 60; ++k) {
    const double t = k / 10.0;
    const double v = t < 4 ? 1.0 : 6.0;
    s.time_s.push_back(t);
    s.pos_m.emplace_back(x, 0.0);
    s.speed_mps.push_back(v);
    s.segment.push_back(0);
    x += v / 10.0;
  }
  return s;
}

TEST(StatsStages, PlayerStatsOfAKnownTrack) {
  StatsOptions o;
  o.team_of[3] = 1;
  o.zones = {{"right", {{3.5, -1}, {20, -1}, {20, 1}, {3.5, 1}}}};
  std::vector<ZoneEvent> events;
  const PlayerStats ps = PlayerStatsOf(StepTrack(3), o, events);
  EXPECT_EQ(ps.team, 1);
  EXPECT_EQ(ps.samples, 61);
  EXPECT_NEAR(ps.distance_m, 4.0 + 12.0, 1e-9);
  EXPECT_EQ(ps.sprints, 1);  // 6 m/s for 2 s
  EXPECT_NEAR(ps.top_speed_mps, 6.0, 1e-9);
  EXPECT_NEAR(ps.mean_speed_mps, 16.0 / 6.0, 1e-9);
  EXPECT_NEAR(ps.band_time_s[0], 4.0, 1e-9);  // below 2 m/s
  EXPECT_NEAR(ps.band_time_s[3], 2.0, 1e-9);  // 5.5..7 m/s
  ASSERT_EQ(events.size(), 1u);
  EXPECT_NEAR(events[0].enter_s, 3.5, 1e-9);  // x = 3.5 at t = 3.5 s
  EXPECT_NEAR(events[0].exit_s, 6.0, 1e-9);
  EXPECT_EQ(ps.speed_profile.size(), 7u);
}

// The top speed comes from 1-s windows that a segment covers whole; a track of pieces shorter
// than that still gets one, from the largest cut window.
TEST(StatsStages, TopSpeedFromWholeWindowsFirst) {
  StatsOptions o;
  std::vector<ZoneEvent> events;
  SmoothTrack s = StepTrack(5);  // 1 m/s for 4 s, then 6 m/s for 2 s
  // The last 0.5 s, a piece of its own at 9 m/s (after a jump the segmentation cut).
  for (size_t k = 56; k < s.time_s.size(); ++k) s.speed_mps[k] = 9.0, s.segment[k] = 1;
  EXPECT_NEAR(PlayerStatsOf(s, o, events).top_speed_mps, 6.0, 1e-9);
  // Only pieces of 0.5 s: the best cut window.
  for (size_t k = 0; k < s.time_s.size(); ++k) s.segment[k] = static_cast<int>(k / 5);
  EXPECT_NEAR(PlayerStatsOf(s, o, events).top_speed_mps, 9.0, 1e-9);
}

TEST(StatsStages, FrameRateAndPairDistances) {
  std::vector<track::TrackRow> rows(4);
  for (int i = 0; i < 4; ++i) {
    rows[i].frame = 1 + 2 * i;  // every other frame, 0.2 s apart: 10 frames/s
    rows[i].time_s = 0.2 * i;
  }
  EXPECT_NEAR(FrameRateOfRows(rows), 10.0, 1e-9);
  rows[2].time_s = 0.1;
  EXPECT_THROW(FrameRateOfRows(rows), fv::Error);
  SmoothTrack b = StepTrack(4);
  for (auto& p : b.pos_m) p.y() = 3.0;
  const auto d = PairDistancesPerSecond({StepTrack(3), b}, 0.0, 6.0);
  ASSERT_EQ(d.size(), 7u);
  EXPECT_EQ(std::get<1>(d[2]), 3);
  EXPECT_EQ(std::get<2>(d[2]), 4);
  EXPECT_NEAR(std::get<3>(d[2]), 3.0, 1e-9);
  // Each second's distance is that of the sample nearest it (it was the first from half a
  // second before): one walking away at 2 m/s, sampled every 0.1 s, from one standing.
  SmoothTrack walker, stander;
  walker.id = 1;
  stander.id = 2;
  for (int k = 0; k <= 30; ++k) {
    walker.time_s.push_back(0.1 * k);
    walker.pos_m.emplace_back(0.2 * k, 0.0);
    stander.time_s.push_back(0.1 * k);
    stander.pos_m.emplace_back(0.0, 0.0);
  }
  const auto apart = PairDistancesPerSecond({walker, stander}, 0.0, 3.0);
  ASSERT_EQ(apart.size(), 4u);
  for (const auto& [sec, a, b, metres] : apart) EXPECT_NEAR(metres, 2.0 * sec, 1e-9) << sec;
}

TEST(Zones, HugeVerticesAndNonStringNamesAreOneLineErrors) {
  const std::string path = fv::testing::TempDir() + "/zones.json";
  std::ofstream(path) << R"([{"name": "box", "polygon": [[0, 0], [1e300, 0], [5, 3]]}])";
  EXPECT_NE(fv::testing::ErrorOf([&] { ReadZones(path); }).find(path), std::string::npos);
  std::ofstream(path) << R"([{"name": 5, "polygon": [[0, 0], [1, 0], [5, 3]]}])";
  const std::string e = fv::testing::ErrorOf([&] { ReadZones(path); });
  EXPECT_NE(e.find(path), std::string::npos) << e;
  std::ofstream(path) << R"([{"name": "box", "polygon": [[0, 0], [1], [5, 3]]}])";
  EXPECT_THAT([&] { ReadZones(path); },
              ThrowsMessage<fv::Error>(HasSubstr("zone 'box': vertex 1 must be an array of 2")));
  EXPECT_THAT([&] { ReadZones(path + ".none"); },
              ThrowsMessage<fv::Error>(HasSubstr("zones file '" + path + ".none' does not exist")));
}

// Zones are columns of the coach's tables and rows of the alerts: a name must tell one from
// another, and a polygon whose outline crosses itself (corners given out of order) has no
// sensible inside.
TEST(Zones, EmptyOrRepeatedNamesAndCrossedOutlinesAreErrors) {
  const std::string path = fv::testing::TempDir() + "/zones.json";
  std::ofstream(path) << R"([{"name": " ", "polygon": [[0, 0], [1, 0], [1, 1]]}])";
  EXPECT_THAT([&] { ReadZones(path); }, ThrowsMessage<fv::Error>(HasSubstr("empty name")));
  std::ofstream(path) << R"([{"name": "a", "polygon": [[0, 0], [1, 0], [1, 1]]},
                            {"name": "a", "polygon": [[0, 0], [2, 0], [2, 2]]}])";
  EXPECT_THAT([&] { ReadZones(path); },
              ThrowsMessage<fv::Error>(HasSubstr("two zones are named 'a'")));
  std::ofstream(path) << R"([{"name": "bow tie", "polygon": [[0, 0], [2, 2], [2, 0], [0, 2]]}])";
  EXPECT_THAT([&] { ReadZones(path); },
              ThrowsMessage<fv::Error>(HasSubstr("zone 'bow tie': its outline crosses itself")));
  std::ofstream(path) << R"([{"name": "box, left", "polygon": [[0, 0], [2, 0], [2, 2], [0, 2]]},
                            {"name": "L", "polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2],
                                                      [0, 2]]}])";
  const auto zones = ReadZones(path);
  ASSERT_EQ(zones.size(), 2u);
  EXPECT_EQ(zones[0].name, "box, left");
}

}  // namespace
}  // namespace fv::stats
