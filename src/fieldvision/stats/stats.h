// Statistics for coaches from player tracks (TRACKS.csv): per player distance covered, speed
// profile, top speed, sprints, time per speed band and per named zone; zone alerts (who entered a
// polygon and when); distances between players over time; heat maps per player and per team and
// a radar (top) view as images, an annotated radar video, stats.json and an index.html report.
// Positions are smoothed before differentiating (a centred Savitzky-Golay filter, quadratic, over
// smooth_window_s, linear where a track's end cuts the window to one side; Savitzky & Golay
// 1964) because per-frame noise inflates distance and speed; jumps faster than max_speed_mps are
// treated as track breaks.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/field/field.h"
#include "fieldvision/field/field_draw.h"
#include "fieldvision/track/mot.h"

namespace fv::stats {

struct Zone {
  std::string name;
  std::vector<Eigen::Vector2d> polygon_m;  // field metres, 3 or more vertices
};

struct StatsOptions {
  // Time of the rows: 0 takes TRACKS.csv's time_s (the video's own time, written by players);
  // > 0 overrides it: frame f (1-based) at (f - 1) / fps seconds.
  double fps = 0.0;
  double smooth_window_s = 1.0;  // smoothing window of positions
  // A player's distance counts a move once the smoothed position lies more than this times the
  // track's position noise (SmoothTrack::noise_m) from where the last counted move ended: the
  // noise smoothing leaves adds up while a player stands (10 cm noise at 25 frames/s: 18 m a
  // minute standing still). Measured on 60-s synthetic tracks at 25 and 10 frames/s with noise
  // 0.05 / 0.1 / 0.2 m, distance (true 0 standing, 6 m drifting 0.1 m/s, 83 m walking, 180 m
  // jogging) with 0 -> 2: standing 9-37 m -> 0-3.3 m, drifting 10.6-36 m -> 6.0-6.4 m, walking
  // 83.2-88.2 m -> 83.1-84.5 m, jogging 180.0-182.7 m -> 179.8-181.1 m; a path reversing at
  // 5 m/s every 2 s (smoothing already cuts its corners: 273 of 300 m) loses up to 4 % more at
  // 0.2 m; a shuttle run as players run it (10 m legs, 4 m/s^2 up to 5 m/s, braking at 5 m/s^2:
  // 192 m a minute) keeps 186-190 m at 0.05-0.2 m of noise, 25 and 10 frames/s. 0: every
  // smoothed step counts.
  double distance_noise_factor = 2.0;
  double max_speed_mps = 12.0;    // faster steps are track breaks (not running)
  double sprint_speed_mps = 5.5;  // a sprint is at least this fast ...
  double sprint_min_s = 1.0;      // ... for at least this long
  // Top speed: the largest mean speed over this long (position noise inflates single samples),
  // from windows a track piece covers whole where it has any.
  double top_speed_window_s = 1.0;
  std::vector<double> speed_bands_mps = {2.0, 4.0, 5.5, 7.0};  // band edges (walk, jog, run...)
  double min_track_s = 1.0;                                    // ignore tracks shorter than this
  std::vector<Zone> zones;             // named polygons for zone time and alerts
  std::map<int, int> team_of;          // optional id -> team (from players --teams)
  std::map<int, std::string> name_of;  // optional id -> roster name (from tracks edit)
  int image_width_px = 900;            // width of heat-map and radar images
  double heat_sigma_m = 1.0;           // Gaussian kernel of the heat maps
  bool write_video = true;             // radar.mp4 (H.264)
  int max_player_heatmaps = 40;        // heat maps per player for the longest tracks

  void Check() const;
};

struct PlayerStats {
  int id = 0;
  int team = -1;
  std::string name;  // roster name, empty when none
  int samples = 0;
  double first_s = 0, last_s = 0;
  // Time followed: first to last less the gaps the track was cut at (distance, speeds, bands and
  // zone times are over it; a gap's ground is not guessed).
  double tracked_s = 0;
  double distance_m = 0;
  double top_speed_mps = 0, mean_speed_mps = 0;  // mean: distance over the time tracked
  double position_noise_m = 0;                   // SmoothTrack::noise_m
  int sprints = 0;
  std::vector<double> band_time_s;  // one per speed band (bands + 1)
  std::map<std::string, double> zone_time_s;
  std::vector<std::pair<double, double>> speed_profile;  // (time_s, speed_mps), 1 per second
};

struct ZoneEvent {
  std::string zone;
  int id = 0;
  double enter_s = 0, exit_s = 0;
};

// Smoothed track: time and position per frame with a position.
struct SmoothTrack {
  int id = 0;
  std::vector<double> time_s;
  std::vector<Eigen::Vector2d> pos_m;
  std::vector<double> speed_mps;
  std::vector<int> segment;  // pieces split at gaps and impossible jumps
  // The raw positions' noise (1 sigma per axis): the robust spread of the change of velocity
  // across each sample, scaled to it (a player's acceleration adds a few mm at 25 frames/s);
  // -1 from SmoothPositions when the track is too short to tell (ComputeStats then gives it the
  // other tracks' median).
  double noise_m = 0;
};

struct StatsResult {
  std::vector<PlayerStats> players;
  std::vector<ZoneEvent> events;
  std::vector<SmoothTrack> tracks;
  // Distances between pairs of players, one sample per second: (time_s, id_a, id_b, metres).
  std::vector<std::tuple<double, int, int, double>> pair_distances;
  double duration_s = 0;
  // Ids followed for less than min_track_s in all (its segments' time: a fragment and a row
  // seconds apart span more), left out of the numbers.
  std::vector<int> left_out;
  double min_track_s = 0;   // as in the options
  double fps = 0;           // the frame rate of the rows' time (median step)
  std::string time_source;  // where the time came from ("TRACKS.csv time_s" or "--fps N")
  std::string Summary() const;
};

// "2 ids left out, ...: 98, 99" for StatsResult::left_out ("" when none).
std::string LeftOutNote(const StatsResult& r);

// Positions come from rows with x_m/y_m, times from time_s (or options.fps); throws fv::Error if
// there are no positions, or no time_s and no options.fps.
StatsResult ComputeStats(const std::vector<track::TrackRow>& rows, const StatsOptions& options);

// The stages of ComputeStats. The frame rate of the rows' time_s: the median step between
// consecutive frames (0 with one frame); throws naming the frame without time or going back.
double FrameRateOfRows(const std::vector<track::TrackRow>& rows);
// One player's distance, speeds, speed bands, sprints, zone times and per-second profile from a
// smoothed track; zone visits are added to `events`.
PlayerStats PlayerStatsOf(const SmoothTrack& track, const StatsOptions& o,
                          std::vector<ZoneEvent>& events);
// Distances between every two players at each whole second in [t_min, t_max] (each player's
// first sample within half a second of it).
std::vector<std::tuple<double, int, int, double>> PairDistancesPerSecond(
    const std::vector<SmoothTrack>& tracks, double t_min, double t_max);

// The time a smoothed track was followed: its steps within segments (gaps left out).
double FollowedS(const SmoothTrack& track);

// Smooths one track's positions (exposed for tests).
SmoothTrack SmoothPositions(int id, const std::vector<double>& time_s,
                            const std::vector<Eigen::Vector2d>& pos_m, const StatsOptions& o);

bool InPolygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p);

// Reads zones from JSON: [{"name": "box", "polygon": [[x, y], ...]}, ...]. Throws naming the file.
std::vector<Zone> ReadZones(const std::string& path);

struct ReportFiles {
  std::vector<std::string> files;
  std::vector<std::string> notes;  // what was skipped and why (e.g. no H.264 encoder)
};

// Time spent per square metre (seconds) in each pixel of `view`: each sample weighs the time to
// the next one, a gap counting at most 1.5 of the track's median step (at least 0.5 s), spread
// by a Gaussian of options.heat_sigma_m; positions outside the view are left out.
cv::Mat TimeSpentPerSquareMetre(const std::vector<const SmoothTrack*>& tracks,
                                const field::TopView& view, const StatsOptions& options);

// Writes into out_dir (created): stats.json; heat maps of time spent (heatmap_all.png,
// heatmap_team<k>.png, heatmap_player<id>.png) with a colour scale in seconds per square metre
// and the zones drawn; radar.png and radar.mp4 (H.264, skipped with a note where OpenCV has no
// encoder); players.csv, speed_profiles.csv, distances.csv; index.html with sortable tables,
// speed-over-time charts per player (inline SVG) and links to every file.
ReportFiles WriteStatsReport(const StatsResult& result, const field::FieldModel& field,
                             const StatsOptions& options, const std::string& out_dir);

}  // namespace fv::stats
