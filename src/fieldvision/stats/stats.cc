#include "fieldvision/stats/stats.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>
#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/strings.h"

namespace fv::stats {

void StatsOptions::Check() const {
  FV_REQUIRE(fps == 0 || (std::isfinite(fps) && fps >= 1e-3 && fps <= 1e4),
             "fps must be 0 (from time_s) or in 0.001..10000 (got {})", fps);
  CheckPositive(smooth_window_s, "smooth_window_s");
  CheckPositive(max_speed_mps, "max_speed_mps");
  CheckPositive(sprint_speed_mps, "sprint_speed_mps");
  CheckNonNegative(sprint_min_s, "sprint_min_s");
  for (size_t i = 0; i < speed_bands_mps.size(); ++i) {
    FV_REQUIRE(speed_bands_mps[i] > 0 && (i == 0 || speed_bands_mps[i] > speed_bands_mps[i - 1]),
               "speed_bands_mps must be positive and increasing");
  }
  CheckNonNegative(min_track_s, "min_track_s");
  CheckNonNegative(top_speed_window_s, "top_speed_window_s");
  CheckNonNegative(distance_noise_factor, "distance_noise_factor");
  for (const auto& z : zones) {
    FV_REQUIRE(z.polygon_m.size() >= 3, "zone '{}' needs at least 3 vertices", z.name);
  }
  FV_REQUIRE(image_width_px >= 100, "image_width_px must be >= 100 (got {})", image_width_px);
  CheckPositive(heat_sigma_m, "heat_sigma_m");
  CheckNonNegative(max_player_heatmaps, "max_player_heatmaps");
}

std::string LeftOutNote(const StatsResult& r) {
  if (r.left_out.empty()) return "";
  std::string ids;
  for (size_t i = 0; i < r.left_out.size() && i < 12; ++i) {
    ids += (i ? ", " : "") + std::to_string(r.left_out[i]);
  }
  if (r.left_out.size() > 12) ids += fmt::format(" and {} more", r.left_out.size() - 12);
  return fmt::format("{} id{} left out, each followed for under {:g} s in all: {}",
                     r.left_out.size(), r.left_out.size() > 1 ? "s" : "", r.min_track_s, ids);
}

std::string StatsResult::Summary() const {
  double total = 0, top = 0;
  int sprints = 0;
  for (const auto& p : players) {
    total += p.distance_m;
    top = std::max(top, p.top_speed_mps);
    sprints += p.sprints;
  }
  std::string s = fmt::format(
      "{} players over {:.1f} s (time from {}, {:.2f} frames/s): {:.0f} m covered in all, top "
      "speed {:.2f} m/s, {} sprints, {} zone entries",
      players.size(), duration_s, time_source, fps, total, top, sprints, events.size());
  if (!left_out.empty()) s += "; " + LeftOutNote(*this);
  return s;
}

bool InPolygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const auto& a = poly[i];
    const auto& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

namespace {

// Whether segments ab and cd cross at a point inside both (touching ends do not count).
bool SegmentsCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const auto side = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q,
                       const Eigen::Vector2d& r) {
    const double cross = (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x();
    return cross > 1e-12 ? 1 : (cross < -1e-12 ? -1 : 0);
  };
  return side(a, b, c) * side(a, b, d) < 0 && side(c, d, a) * side(c, d, b) < 0;
}

// Whether two edges of the closed polygon that do not share a corner cross.
bool CrossesItself(const std::vector<Eigen::Vector2d>& polygon) {
  const size_t n = polygon.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours through the closing edge
      if (SegmentsCross(polygon[i], polygon[(i + 1) % n], polygon[j], polygon[(j + 1) % n])) {
        return true;
      }
    }
  }
  return false;
}

}  // namespace

std::vector<Zone> ReadZones(const std::string& path) {
  const nlohmann::json j = util::ReadJsonFile(path, "zones");
  FV_REQUIRE(j.is_array(), "zones file '{}': expected an array of {{name, polygon}}", path);
  std::vector<Zone> zones;
  for (size_t i = 0; i < j.size(); ++i) {
    Zone z;
    FV_REQUIRE(util::JsonHas(j[i], "polygon") && j[i]["polygon"].is_array(),
               "zones file '{}': zone {} has no polygon", path, i);
    z.name = util::JsonString(j[i], "name", fmt::format("zones file '{}': zone {}", path, i),
                              fmt::format("zone{}", i + 1));
    const std::string ctx = fmt::format("zones file '{}': zone '{}'", path, z.name);
    for (const auto& v : j[i]["polygon"]) {
      z.polygon_m.push_back(
          util::JsonVectorOf<2>(v, fmt::format("{}: vertex {}", ctx, z.polygon_m.size())));
      // Field coordinates: metres from the centre; 10 km is beyond any field.
      FV_REQUIRE(z.polygon_m.back().cwiseAbs().maxCoeff() <= 1e4,
                 "{} has a vertex out of range ({}, {})", ctx, z.polygon_m.back().x(),
                 z.polygon_m.back().y());
    }
    FV_REQUIRE(z.polygon_m.size() >= 3, "{} needs 3 or more vertices", ctx);
    FV_REQUIRE(!util::Trim(z.name).empty(), "zones file '{}': zone {} has an empty name", path, i);
    FV_REQUIRE(z.name.find_first_of("\n\r") == std::string::npos, "{}: a name on one line, please",
               ctx);
    for (const Zone& other : zones) {
      FV_REQUIRE(other.name != z.name, "zones file '{}': two zones are named '{}'", path, z.name);
    }
    FV_REQUIRE(!CrossesItself(z.polygon_m),
               "{}: its outline crosses itself (give the corners in order around it)", ctx);
    zones.push_back(z);
  }
  return zones;
}

namespace {

// SmoothTrack::noise_m: the change of velocity across each sample, (p[i+1] - p[i]) / dt2 -
// (p[i] - p[i-1]) / dt1, is zero for straight steady motion at any spacing and has variance
// sigma^2 (1/dt1^2 + (1/dt1 + 1/dt2)^2 + 1/dt2^2) under white noise; its robust spread over that
// scale is sigma. -1 with fewer than five such samples (too short to tell).
double PositionNoise(const std::vector<double>& t, const std::vector<Eigen::Vector2d>& p,
                     const std::vector<int>& segment) {
  std::vector<double> scaled;
  for (size_t i = 1; i + 1 < t.size(); ++i) {
    if (segment[i - 1] != segment[i + 1]) continue;
    const double dt1 = t[i] - t[i - 1], dt2 = t[i + 1] - t[i];
    if (!(dt1 > 0 && dt2 > 0)) continue;
    const Eigen::Vector2d d = (p[i + 1] - p[i]) / dt2 - (p[i] - p[i - 1]) / dt1;
    const double scale =
        std::sqrt(1 / (dt1 * dt1) + (1 / dt1 + 1 / dt2) * (1 / dt1 + 1 / dt2) + 1 / (dt2 * dt2));
    scaled.push_back(d.x() / scale);
    scaled.push_back(d.y() / scale);
  }
  return scaled.size() < 10 ? -1.0 : util::RobustSigma(scaled);
}

}  // namespace

double FollowedS(const SmoothTrack& s) {
  double followed_s = 0;
  for (size_t i = 1; i < s.time_s.size(); ++i) {
    if (s.segment[i] == s.segment[i - 1]) followed_s += s.time_s[i] - s.time_s[i - 1];
  }
  return followed_s;
}

SmoothTrack SmoothPositions(int id, const std::vector<double>& t,
                            const std::vector<Eigen::Vector2d>& p, const StatsOptions& o) {
  SmoothTrack s;
  s.id = id;
  const size_t n = t.size();
  s.time_s = t;
  s.pos_m.resize(n);
  s.speed_mps.assign(n, 0.0);
  s.segment.assign(n, 0);
  // Segments: split at gaps (three of the track's own steps, at least 0.5 s: a track sampled
  // every 0.52 s was all gaps, 0 m) and at jumps no person makes, beyond what the position
  // noise makes of a step (5 sigma of a step's length: noise of 0.2 m split 5 % of the steps at
  // 60 fps, 144-151 m of 180 m covered).
  // The track's own step counts from five rows on and up to 2/3 s (a few scattered rows are all
  // gaps, not a slow sampling: two rows 10 s apart were bridged as 30 m).
  std::vector<double> steps_s;
  for (size_t i = 1; i < n; ++i) steps_s.push_back(t[i] - t[i - 1]);
  const double own_step_s = n >= 5 ? std::min(util::Median(steps_s), 2.0 / 3.0) : 0.0;
  const double max_gap_s = std::max({0.5, 3.0 * own_step_s, o.fps > 0 ? 3.0 / o.fps : 0.0});
  for (size_t i = 1; i < n; ++i) s.segment[i] = s.segment[i - 1] + (steps_s[i - 1] > max_gap_s);
  const double noise_m = std::max(0.0, PositionNoise(t, p, s.segment));
  const double jump_m = 0.5 + 5.0 * std::sqrt(2.0) * noise_m;
  for (size_t i = 1; i < n; ++i) {
    const double dt = t[i] - t[i - 1];
    const bool brk = dt > max_gap_s || (p[i] - p[i - 1]).norm() > o.max_speed_mps * dt + jump_m;
    s.segment[i] = s.segment[i - 1] + (brk ? 1 : 0);
  }
  s.noise_m = PositionNoise(t, p, s.segment);
  // At least a neighbour on each side (a track sampled twice a second had no speed at all).
  const double half = std::max(0.5 * o.smooth_window_s, 1.01 * own_step_s);
  for (size_t i = 0; i < n; ++i) {
    // Local quadratic fit (Savitzky-Golay) over the neighbours in the same segment.
    size_t a = i, b = i;
    while (a > 0 && s.segment[a - 1] == s.segment[i] && t[i] - t[a - 1] <= half) --a;
    while (b + 1 < n && s.segment[b + 1] == s.segment[i] && t[b + 1] - t[i] <= half) ++b;
    const int m = static_cast<int>(b - a + 1);
    if (m < 3) {
      s.pos_m[i] = p[i];
      continue;
    }
    // Near a segment's end the window is one-sided and a quadratic's slope at its end swings
    // with the noise: a line there.
    const double before_s = t[i] - t[a], after_s = t[b] - t[i];
    const int degree = std::min(before_s, after_s) < 0.5 * std::max(before_s, after_s) ? 1 : 2;
    Eigen::MatrixXd A(m, degree + 1);
    Eigen::MatrixXd Y(m, 2);
    for (int k = 0; k < m; ++k) {
      const double dt = t[a + k] - t[i];
      A(k, 0) = 1.0;
      A(k, 1) = dt;
      if (degree == 2) A(k, 2) = dt * dt;
      Y.row(k) = p[a + k].transpose();
    }
    const Eigen::MatrixXd coef = (A.transpose() * A).ldlt().solve(A.transpose() * Y);
    s.pos_m[i] = coef.row(0).transpose();
    s.speed_mps[i] = coef.row(1).norm();
  }
  return s;
}

namespace {

// Time of a row: (frame - 1) / fps when fps > 0, else its time_s.
double TimeOf(const track::TrackRow& r, double fps) {
  return fps > 0 ? (r.frame - 1) / fps : *r.time_s;
}

// Top speed: the largest mean speed over top_speed_window_s within a segment (the largest
// instantaneous speed grows with the position noise: on the synthetic players scene walkers at
// 1.4-1.6 m/s got 1.9-2.0 m/s), from windows that the segment covers whole; a window cut by a
// segment's end holds the end's noisier speeds more heavily (the largest partial one when no
// window is whole).
double TopSpeed(const SmoothTrack& s, const StatsOptions& o) {
  double top_whole = -1, top_partial = 0;
  const size_t n = s.time_s.size();
  const double half = 0.5 * o.top_speed_window_s;
  size_t a = 0, b = 0;
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    // Window [a, b) of samples within half a window of i, in i's segment.
    while (b < n && s.time_s[b] <= s.time_s[i] + half && s.segment[b] == s.segment[i]) {
      sum += std::min(s.speed_mps[b], o.max_speed_mps);
      ++b;
    }
    while (a < i && (s.time_s[a] < s.time_s[i] - half || s.segment[a] != s.segment[i])) {
      sum -= std::min(s.speed_mps[a], o.max_speed_mps);
      ++a;
    }
    if (b <= a) continue;
    const double mean = sum / static_cast<double>(b - a);
    // Whole: on each side a sample of the segment was left out, or the last one in lies on the
    // window's edge.
    const bool whole_before =
        (a > 0 && s.segment[a - 1] == s.segment[i]) || s.time_s[a] <= s.time_s[i] - half + 1e-9;
    const bool whole_after =
        (b < n && s.segment[b] == s.segment[i]) || s.time_s[b - 1] >= s.time_s[i] + half - 1e-9;
    if (whole_before && whole_after) top_whole = std::max(top_whole, mean);
    top_partial = std::max(top_partial, mean);
  }
  return top_whole >= 0 ? top_whole : top_partial;
}

}  // namespace

double FrameRateOfRows(const std::vector<track::TrackRow>& rows) {
  std::map<int, double> time_of_frame;
  for (const auto& r : rows) {
    FV_REQUIRE(r.time_s.has_value(),
               "the tracks have no time_s (frame {}): re-run players (it writes the video's "
               "time) or give --fps",
               r.frame);
    time_of_frame[r.frame] = *r.time_s;
  }
  std::vector<double> steps;
  for (auto it = time_of_frame.begin(); std::next(it) != time_of_frame.end(); ++it) {
    const auto next = std::next(it);
    FV_REQUIRE(next->second > it->second,
               "the tracks' time_s does not increase from frame {} to frame {}", it->first,
               next->first);
    steps.push_back((next->second - it->second) / (next->first - it->first));
  }
  return steps.empty() ? 0.0 : 1.0 / util::NearestRankPercentile(steps, 0.5);
}

PlayerStats PlayerStatsOf(const SmoothTrack& s, const StatsOptions& o,
                          std::vector<ZoneEvent>& events) {
  const std::vector<double>& t = s.time_s;
  PlayerStats ps;
  ps.id = s.id;
  const auto team = o.team_of.find(s.id);
  ps.team = team == o.team_of.end() ? -1 : team->second;
  const auto name = o.name_of.find(s.id);
  if (name != o.name_of.end()) ps.name = name->second;
  ps.samples = static_cast<int>(t.size());
  ps.first_s = t.front();
  ps.last_s = t.back();
  ps.band_time_s.assign(o.speed_bands_mps.size() + 1, 0.0);
  for (const auto& z : o.zones) ps.zone_time_s[z.name] = 0.0;
  ps.top_speed_mps = TopSpeed(s, o);
  ps.position_noise_m = std::max(s.noise_m, 0.0);
  const double dead_band_m = o.distance_noise_factor * ps.position_noise_m;
  Eigen::Vector2d counted_to = s.pos_m.front();  // where the last counted move ended
  double sprint_run = 0;
  std::map<std::string, std::optional<double>> inside_since;
  std::map<int, std::pair<double, int>> per_second;  // second -> (sum, count)
  for (size_t i = 0; i < t.size(); ++i) {
    const bool joined = i + 1 < t.size() && s.segment[i + 1] == s.segment[i];
    const double dt = joined ? t[i + 1] - t[i] : 0.0;
    if (i > 0 && s.segment[i] != s.segment[i - 1]) counted_to = s.pos_m[i];
    if (joined) {
      const double moved = (s.pos_m[i + 1] - counted_to).norm();
      if (moved > dead_band_m) {
        ps.distance_m += moved;
        counted_to = s.pos_m[i + 1];
      }
    }
    const double v = std::min(s.speed_mps[i], o.max_speed_mps);
    size_t band = 0;
    while (band < o.speed_bands_mps.size() && v >= o.speed_bands_mps[band]) ++band;
    ps.band_time_s[band] += dt;
    if (v >= o.sprint_speed_mps && joined) {
      sprint_run += dt;
    } else {
      if (sprint_run >= o.sprint_min_s) ps.sprints++;
      sprint_run = 0;
    }
    auto& sec = per_second[static_cast<int>(std::floor(t[i]))];
    sec.first += v;
    sec.second++;
    for (const auto& z : o.zones) {
      const bool in = InPolygon(z.polygon_m, s.pos_m[i]);
      if (in) ps.zone_time_s[z.name] += dt;
      auto& since = inside_since[z.name];
      if (in && !since) since = t[i];
      if ((!in || i + 1 == t.size()) && since) {
        events.push_back({z.name, s.id, *since, t[i]});
        since.reset();
      }
    }
  }
  if (sprint_run >= o.sprint_min_s) ps.sprints++;
  ps.tracked_s = FollowedS(s);
  ps.mean_speed_mps = ps.tracked_s > 0 ? ps.distance_m / ps.tracked_s : 0.0;
  for (const auto& [sec, sc] : per_second) {
    ps.speed_profile.emplace_back(sec, sc.first / sc.second);
  }
  return ps;
}

std::vector<std::tuple<double, int, int, double>> PairDistancesPerSecond(
    const std::vector<SmoothTrack>& tracks, double t_min, double t_max) {
  std::vector<std::tuple<double, int, int, double>> out;
  for (int sec = static_cast<int>(std::ceil(t_min)); sec <= t_max; ++sec) {
    std::vector<std::pair<int, Eigen::Vector2d>> at;
    for (const auto& s : tracks) {
      // The sample nearest the second, within half a second (the first at or after sec - 0.5
      // gave the distance of half a second before: 1.1 m off on average).
      const auto after = std::lower_bound(s.time_s.begin(), s.time_s.end(), double(sec));
      auto best = after;
      if (after == s.time_s.end() ||
          (after != s.time_s.begin() && sec - *std::prev(after) < *after - sec)) {
        best = after == s.time_s.begin() ? after : std::prev(after);
      }
      if (best == s.time_s.end() || std::abs(*best - sec) > 0.5) continue;
      at.emplace_back(s.id, s.pos_m[best - s.time_s.begin()]);
    }
    for (size_t i = 0; i < at.size(); ++i) {
      for (size_t j = i + 1; j < at.size(); ++j) {
        out.emplace_back(sec, at[i].first, at[j].first, (at[i].second - at[j].second).norm());
      }
    }
  }
  return out;
}

namespace {

// Players that move faster than anyone runs (12.5 m/s) over a second or more, half the time:
// positions not in metres. (From one row to the next, 20 cm of position noise at 100 frames/s
// is 28 m/s.)
void CheckPlayerSpeedUnits(std::map<int, std::vector<const track::TrackRow*>>& by_id, double fps) {
  constexpr double kMaxMedianSpeedMps = 20.0, kBaselineS = 1.0;
  std::vector<double> speeds_mps;
  for (auto& [id, rs] : by_id) {
    std::sort(rs.begin(), rs.end(), [](auto* a, auto* b) { return a->frame < b->frame; });
    size_t j = 0;
    for (size_t i = 0; i < rs.size(); ++i) {
      const double t = TimeOf(*rs[i], fps);
      j = std::max(j, i + 1);
      while (j < rs.size() && TimeOf(*rs[j], fps) - t < kBaselineS) ++j;
      if (j >= rs.size()) break;
      speeds_mps.push_back(std::hypot(*rs[j]->x_m - *rs[i]->x_m, *rs[j]->y_m - *rs[i]->y_m) /
                           (TimeOf(*rs[j], fps) - t));
    }
  }
  if (speeds_mps.empty()) return;
  const double median = util::Median(speeds_mps);
  FV_REQUIRE(median < kMaxMedianSpeedMps,
             "the players move {:.4g} m/s over a second (the median), faster than anyone runs: "
             "are x_m, y_m metres (not millimetres or pixels)?",
             median);
}

}  // namespace

StatsResult ComputeStats(const std::vector<track::TrackRow>& rows, const StatsOptions& options) {
  options.Check();
  std::map<int, std::vector<const track::TrackRow*>> by_id;
  for (const auto& r : rows) {
    if (r.x_m && r.y_m) by_id[r.id].push_back(&r);
    FV_REQUIRE(options.fps <= 0 || r.frame >= 1,
               "frame {}: tracks number frames from 1 (MOTChallenge), and with a frame rate "
               "given time is (frame - 1) / fps",
               r.frame);
  }
  FV_REQUIRE(!rows.empty(), "the tracks have no rows (an empty file, or every id dropped)");
  FV_REQUIRE(!by_id.empty(),
             "the tracks have no field positions (x_m, y_m): run players with a calibrated camera");
  StatsResult res;
  res.min_track_s = options.min_track_s;
  StatsOptions o = options;
  if (options.fps > 0) {
    res.time_source = fmt::format("--fps {:g}", options.fps);
    res.fps = options.fps;
  } else {
    // The rate of the rows' own times: the median step between consecutive frames.
    res.fps = FrameRateOfRows(rows);
    FV_REQUIRE(res.fps == 0 || res.fps >= 0.2,
               "the tracks' time_s steps {:.4g} s a frame (the median; {:.3g} frames/s): are "
               "they seconds, not milliseconds? (--fps gives the video's rate instead)",
               1 / res.fps, res.fps);
    res.time_source = "TRACKS.csv time_s";
    o.fps = res.fps > 0 ? res.fps : 25.0;  // only for the gap rule of SmoothPositions
  }
  CheckPlayerSpeedUnits(by_id, options.fps);
  double t_min = 1e300, t_max = -1e300;
  for (auto& [id, rs] : by_id) {
    std::sort(rs.begin(), rs.end(), [](auto* a, auto* b) { return a->frame < b->frame; });
    std::vector<double> t;
    std::vector<Eigen::Vector2d> p;
    for (const auto* r : rs) {
      const double time = TimeOf(*r, options.fps);
      if (!t.empty() && time <= t.back()) continue;  // duplicate frame
      t.push_back(time);
      p.emplace_back(*r->x_m, *r->y_m);
    }
    SmoothTrack s = SmoothPositions(id, t, p, o);
    if (FollowedS(s) < o.min_track_s) {
      res.left_out.push_back(id);
      continue;
    }
    res.tracks.push_back(std::move(s));
    t_min = std::min(t_min, t.front());
    t_max = std::max(t_max, t.back());
  }
  FV_REQUIRE(!res.tracks.empty(), "no player is followed for {} s or more ({} ids, each shorter)",
             o.min_track_s, res.left_out.size());
  // A track too short to tell its noise takes the others' median (one camera, one tracker).
  std::vector<double> known;
  for (const SmoothTrack& s : res.tracks) {
    if (s.noise_m >= 0) known.push_back(s.noise_m);
  }
  const double median_noise_m = known.empty() ? 0.0 : util::Median(known);
  for (SmoothTrack& s : res.tracks) {
    if (s.noise_m < 0) s.noise_m = median_noise_m;
    res.players.push_back(PlayerStatsOf(s, o, res.events));
  }
  res.duration_s = t_max - t_min;
  std::sort(res.events.begin(), res.events.end(),
            [](const ZoneEvent& a, const ZoneEvent& b) { return a.enter_s < b.enter_s; });
  // Distances between players once per second (nearest sample within half a second).
  res.pair_distances = PairDistancesPerSecond(res.tracks, t_min, t_max);
  return res;
}

}  // namespace fv::stats
