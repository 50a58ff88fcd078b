// Images, video, JSON and HTML of the statistics (declared in stats.h).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/field/field_draw.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/io/video_writer.h"
#include "fieldvision/stats/stats.h"
#include "fieldvision/track/overlay.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/stats.h"

namespace fv::stats {
namespace fs = std::filesystem;
namespace {

void Write(const std::string& path, const cv::Mat& img, ReportFiles& files) {
  io::WriteImage(path, img);
  files.files.push_back(path);
}

// Zones drawn on a top view: outline and name.
void DrawZones(cv::Mat& img, const std::vector<Zone>& zones, const field::TopView& view) {
  for (const auto& z : zones) {
    std::vector<cv::Point> pts;
    for (const auto& v : z.polygon_m) pts.push_back(view.ToPixel(v));
    cv::polylines(img, pts, true, {0, 255, 255}, 2, cv::LINE_AA);
    cv::Point c(0, 0);
    for (const auto& p : pts) c += p;
    c = cv::Point(c.x / static_cast<int>(pts.size()), c.y / static_cast<int>(pts.size()));
    cv::putText(img, z.name, c, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 3, cv::LINE_AA);
    cv::putText(img, z.name, c, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 255, 255}, 1, cv::LINE_AA);
  }
}

// The longest time a sample of `s` stands for: a gap in the track counts no more than this,
// 1.5 of its median step (a track sampled every 10 s still fills its map), at least 0.5 s.
double MaxSampleWeight(const SmoothTrack& s) {
  std::vector<double> steps;
  for (size_t i = 1; i < s.time_s.size(); ++i) steps.push_back(s.time_s[i] - s.time_s[i - 1]);
  if (steps.empty()) return 0.5;
  return std::max(0.5, 1.5 * util::RankPercentile(std::move(steps), 0.5));
}

}  // namespace

cv::Mat TimeSpentPerSquareMetre(const std::vector<const SmoothTrack*>& tracks,
                                const field::TopView& view, const StatsOptions& o) {
  cv::Mat acc = cv::Mat::zeros(view.size, CV_32F);
  for (const auto* s : tracks) {
    const size_t n = s->pos_m.size();
    const double max_dt = MaxSampleWeight(*s);
    for (size_t i = 0; i < n; ++i) {
      double dt = 0;
      if (i + 1 < n) {
        dt = s->time_s[i + 1] - s->time_s[i];
      } else if (n > 1) {
        dt = s->time_s[i] - s->time_s[i - 1];
      }
      dt = std::min(dt, max_dt);
      const cv::Point2d px = view.ToPixel(s->pos_m[i]);
      const int x = static_cast<int>(px.x), y = static_cast<int>(px.y);
      if (x >= 0 && y >= 0 && x < acc.cols && y < acc.rows) {
        acc.at<float>(y, x) += static_cast<float>(dt);
      }
    }
  }
  const double sigma = std::max(1.0, o.heat_sigma_m * view.px_per_m);
  cv::GaussianBlur(acc, acc, cv::Size(), sigma);
  return acc * (view.px_per_m * view.px_per_m);  // seconds per pixel -> per square metre
}

namespace {

// The top of the colour scale: the 99th percentile of the cells with time (one person standing
// still in one spot does not take the whole range).
double ScaleMax(const cv::Mat& density) {
  std::vector<double> v;
  double mx = 0;
  cv::minMaxLoc(density, nullptr, &mx);
  for (int y = 0; y < density.rows; ++y) {
    for (int x = 0; x < density.cols; ++x) {
      const float d = density.at<float>(y, x);
      if (d > 0.01 * mx) v.push_back(d);
    }
  }
  if (v.empty()) return 0;
  return std::max(util::RankPercentile(std::move(v), 0.99), 1e-6);
}

// The colour map's 256 colours (JET), made once.
const cv::Mat& JetColours() {
  static const cv::Mat kColours = [] {
    cv::Mat ramp(1, 256, CV_8U), c;
    for (int i = 0; i < 256; ++i) ramp.at<uchar>(0, i) = static_cast<uchar>(i);
    cv::applyColorMap(ramp, c, cv::COLORMAP_JET);
    return c;
  }();
  return kColours;
}

// The heat map's colour over the field at a share `f` of the scale's top (the bar shows the same).
cv::Vec3b HeatColour(double f, const cv::Vec3b& under) {
  f = std::clamp(f, 0.0, 1.0);
  const cv::Vec3b c = JetColours().at<cv::Vec3b>(0, cv::saturate_cast<uchar>(255 * f));
  const double a = std::min(0.85, std::sqrt(f));
  cv::Vec3b out;
  for (int k = 0; k < 3; ++k) out[k] = cv::saturate_cast<uchar>((1 - a) * under[k] + a * c[k]);
  return out;
}

// Heat map of time spent over the field drawing (axes in metres), with its colour scale (seconds
// per square metre, the colours as they look over the field) on the right and the zones drawn.
cv::Mat HeatMap(const std::vector<const SmoothTrack*>& tracks, const field::FieldModel& field,
                const field::TopView& view, const StatsOptions& o, const std::string& title) {
  const cv::Mat density = TimeSpentPerSquareMetre(tracks, view, o);
  const double vmax = ScaleMax(density);
  const field::FieldDrawOptions draw;
  cv::Mat img = field::DrawField(field, view, draw);
  if (vmax > 0) {
    for (int y = 0; y < img.rows; ++y) {
      for (int x = 0; x < img.cols; ++x) {
        const double f = density.at<float>(y, x) / vmax;
        cv::Vec3b& d = img.at<cv::Vec3b>(y, x);
        d = HeatColour(f, d);
      }
    }
    field::DrawFieldLines(img, field, view, cv::Scalar(255, 255, 255), 1);
  }
  DrawZones(img, o.zones, view);
  cv::putText(img, title, {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.7, {255, 255, 255}, 2);
  if (vmax <= 0) {
    cv::putText(img, "no position inside the picture", {10, img.rows / 2}, cv::FONT_HERSHEY_SIMPLEX,
                0.8, {255, 255, 255}, 2, cv::LINE_AA);
  }
  img = field::FrameTopView(img, view, "");
  // Colour scale: a bar with ticks at 0, 1/2 and the top (>= top: the few busiest cells).
  const int panel_w = 110, bar_w = 22, top = 52, bottom = img.rows - 50;
  cv::Mat out(img.rows, img.cols + panel_w, CV_8UC3, cv::Scalar(255, 255, 255));
  img.copyTo(out(cv::Rect(0, 0, img.cols, img.rows)));
  if (vmax <= 0) return out;
  const int x0 = img.cols + 12;
  cv::putText(out, "time spent", {x0 - 4, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 1,
              cv::LINE_AA);
  cv::putText(out, "s per m^2", {x0 - 4, 32}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 1,
              cv::LINE_AA);
  const cv::Scalar& bg = draw.background;
  const cv::Vec3b field_colour(cv::saturate_cast<uchar>(bg[0]), cv::saturate_cast<uchar>(bg[1]),
                               cv::saturate_cast<uchar>(bg[2]));
  for (int y = top; y <= bottom; ++y) {
    const double f = double(bottom - y) / std::max(1, bottom - top);
    cv::line(out, {x0, y}, {x0 + bar_w, y}, cv::Scalar(HeatColour(f, field_colour)), 1);
  }
  cv::rectangle(out, {x0, top}, {x0 + bar_w, bottom}, {0, 0, 0}, 1);
  for (int k = 0; k <= 2; ++k) {
    const int y = bottom - k * (bottom - top) / 2;
    cv::line(out, {x0 + bar_w, y}, {x0 + bar_w + 5, y}, {0, 0, 0}, 1);
    const std::string label = fmt::format("{}{:.2g}", k == 2 ? ">=" : "", vmax * k / 2.0);
    cv::putText(out, label, {x0 + bar_w + 8, y + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {0, 0, 0}, 1,
                cv::LINE_AA);
  }
  return out;
}

// A player's label: the roster name, else the id.
std::string LabelOf(int id, const std::map<int, std::string>& name_of) {
  const auto n = name_of.find(id);
  return n != name_of.end() ? n->second : std::to_string(id);
}

// The radar (top) view at time t: trails of the last seconds and current positions with labels.
void DrawRadar(cv::Mat& img, const StatsResult& r, const field::TopView& view, double t,
               double trail_s, const StatsOptions& o) {
  for (const auto& s : r.tracks) {
    const auto tm = o.team_of.find(s.id);
    const cv::Scalar c = track::TrackColour(s.id, tm == o.team_of.end() ? -1 : tm->second);
    std::optional<cv::Point2d> last;
    size_t last_i = 0;
    for (size_t i = 0; i < s.time_s.size(); ++i) {
      if (s.time_s[i] > t) break;
      if (s.time_s[i] < t - trail_s) continue;
      const cv::Point2d p = view.ToPixel(s.pos_m[i]);
      if (last && s.segment[i] == s.segment[last_i]) cv::line(img, *last, p, c, 2, cv::LINE_AA);
      last = p;
      last_i = i;
    }
    if (!last) continue;
    // Where the player is now (filled), or where the track ended (hollow): every trail named.
    const bool now = t - s.time_s[last_i] < 0.5;
    if (now) cv::circle(img, *last, 7, c, cv::FILLED, cv::LINE_AA);
    cv::circle(img, *last, 7, now ? cv::Scalar(0, 0, 0) : c, now ? 1 : 2, cv::LINE_AA);
    cv::putText(img, LabelOf(s.id, o.name_of), *last + cv::Point2d(8, -8), cv::FONT_HERSHEY_SIMPLEX,
                0.5, {255, 255, 255}, 1, cv::LINE_AA);
  }
}

// Speed over time of one player as an inline SVG chart (axes in s and m/s, sprint threshold
// dashed), on a time axis shared by all players.
std::string SpeedChartSvg(const PlayerStats& p, double t0, double t1, double vmax, double sprint) {
  const double w = 460, h = 130, left = 40, right = 10, top = 10, bottom = 28;
  const double span = std::max(1e-6, t1 - t0);
  auto X = [&](double t) { return left + (t - t0) / span * (w - left - right); };
  auto Y = [&](double v) { return top + (1 - std::min(v, vmax) / vmax) * (h - top - bottom); };
  std::string svg = fmt::format(
      "<svg width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\" font-size=\"10\">"
      "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#f8f8f8\" stroke=\"#999\"/>",
      w, h, w, h, left, top, w - left - right, h - top - bottom);
  for (int k = 0; k <= 4; ++k) {  // speed ticks
    const double v = vmax * k / 4;
    svg += fmt::format(
        "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#ddd\"/>"
        "<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\">{:.3g}</text>",
        left, Y(v), w - right, Y(v), left - 3, Y(v) + 3, v);
  }
  for (int k = 0; k <= 5; ++k) {  // time ticks
    const double t = t0 + span * k / 5;
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{:.0f}</text>", X(t),
                       h - bottom + 12, t);
  }
  svg += fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">time (s)</text>"
      "<text x=\"10\" y=\"{:.1f}\" transform=\"rotate(-90 10 {:.1f})\" "
      "text-anchor=\"middle\">m/s</text>",
      left + 0.5 * (w - left - right), h - 3, top + 0.5 * (h - top - bottom),
      top + 0.5 * (h - top - bottom));
  if (sprint < vmax) {
    svg += fmt::format(
        "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#c00\" "
        "stroke-dasharray=\"4 3\"><title>sprint threshold {:g} m/s</title></line>",
        left, Y(sprint), w - right, Y(sprint), sprint);
  }
  std::string pts;
  for (const auto& [t, v] : p.speed_profile) pts += fmt::format("{:.1f},{:.1f} ", X(t + 0.5), Y(v));
  svg += fmt::format(
      "<polyline fill=\"none\" stroke=\"#1060c0\" stroke-width=\"1.5\" points=\"{}\"/>", pts);
  return svg + "</svg>";
}

std::string Html(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') {
      out += "&lt;";
    } else if (c == '>') {
      out += "&gt;";
    } else if (c == '&') {
      out += "&amp;";
    } else if (c == '"') {
      out += "&quot;";
    } else {
      out += c;
    }
  }
  return out;
}

// Sorting of tables by a click on a header (numbers as numbers), for the report.
constexpr const char* kSortScript = R"(<script>
document.querySelectorAll('table.sortable th').forEach(function (th, col) {
  th.style.cursor = 'pointer';
  th.title = 'sort';
  th.addEventListener('click', function () {
    var table = th.closest('table'), rows = Array.from(table.querySelectorAll('tr')).slice(1);
    var asc = th.dataset.asc !== '1';
    th.dataset.asc = asc ? '1' : '0';
    rows.sort(function (a, b) {
      var x = a.children[col].textContent, y = b.children[col].textContent;
      var nx = parseFloat(x), ny = parseFloat(y);
      var c = (!isNaN(nx) && !isNaN(ny)) ? nx - ny : x.localeCompare(y);
      return asc ? c : -c;
    });
    rows.forEach(function (r) { table.appendChild(r); });
  });
});
</script>
)";

// What the report's parts share.
struct ReportParts {
  ReportParts(const StatsResult& r, const StatsOptions& o, std::string out_dir,
              const field::TopView& view)
      : r(r), o(o), out_dir(std::move(out_dir)), view(view) {}
  const StatsResult& r;
  const StatsOptions& o;
  std::string out_dir;
  field::TopView view;
  double t0 = 1e300, t1 = -1e300;  // first and last time of all tracks
  std::vector<std::string> band_names;
  std::vector<int> teams;        // with a heat map
  std::vector<int> player_maps;  // ids with a heat map, sorted
  std::string radar_video;       // file name, empty when not written
};

// Speed band names: "0-2", "2-4", ..., "7-up".
std::vector<std::string> BandNames(const StatsOptions& o) {
  std::vector<std::string> band_names;
  for (size_t b = 0; b <= o.speed_bands_mps.size(); ++b) {
    const std::string lo = b == 0 ? "0" : fmt::format("{:g}", o.speed_bands_mps[b - 1]);
    const std::string hi =
        b < o.speed_bands_mps.size() ? fmt::format("{:g}", o.speed_bands_mps[b]) : "up";
    band_names.push_back(fmt::format("{}-{}", lo, hi));
  }
  return band_names;
}

// The top view of the heat maps and the radar: the field and its surround widened to the
// positions beyond them, up to kMaxBeyondM; positions farther out (tracks of another field, or
// a wrong camera) are left out and said in a note.
constexpr double kMinMarginM = 2.0, kMaxBeyondM = 15.0;

field::TopView ReportView(const StatsResult& r, const field::FieldModel& field,
                          const StatsOptions& o, ReportFiles* files) {
  const double hx = field.HalfLengthWithSurround(), hy = field.HalfWidthWithSurround();
  double beyond = 0;
  long long outside = 0, positions = 0;
  std::set<int> outside_ids;
  for (const auto& s : r.tracks) {
    for (const auto& p : s.pos_m) {
      const double b = std::max(std::abs(p.x()) - hx, std::abs(p.y()) - hy);
      ++positions;
      if (b > kMaxBeyondM) {
        ++outside;
        outside_ids.insert(s.id);
      } else {
        beyond = std::max(beyond, b);
      }
    }
  }
  if (outside > 0) {
    files->notes.push_back(fmt::format(
        "{} of {} positions ({} players) lie more than {:g} m outside field '{}' and its surround: "
        "the heat maps and the radar leave them out (the tables count them); were the tracks made "
        "on this field, with the right camera?",
        outside, positions, outside_ids.size(), kMaxBeyondM, field.name));
  }
  const int width_px = std::max(100, o.image_width_px - field::kTopViewFrameWidthPx);
  return field::TopView::ForField(field, width_px, std::max(kMinMarginM, beyond + 1.0));
}

// Heat maps: all players, each team and the longest tracks.
void WriteHeatMaps(const field::FieldModel& field, ReportParts& rp, ReportFiles& files) {
  const StatsResult& r = rp.r;
  const StatsOptions& o = rp.o;
  const std::string& out_dir = rp.out_dir;
  const field::TopView& view = rp.view;
  std::vector<const SmoothTrack*> all;
  std::map<int, std::vector<const SmoothTrack*>> by_team;
  std::map<int, const PlayerStats*> player_of;
  for (const auto& p : r.players) player_of[p.id] = &p;
  for (const auto& s : r.tracks) {
    all.push_back(&s);
    const int team = player_of.count(s.id) ? player_of[s.id]->team : -1;
    if (team >= 0) by_team[team].push_back(&s);
  }
  Write(out_dir + "/heatmap_all.png", HeatMap(all, field, view, o, "all players"), files);
  for (const auto& [team, ts] : by_team) {
    Write(fmt::format("{}/heatmap_team{}.png", out_dir, team),
          HeatMap(ts, field, view, o, fmt::format("team {}", team)), files);
    rp.teams.push_back(team);
  }
  std::vector<const SmoothTrack*> longest = all;
  std::sort(longest.begin(), longest.end(),
            [](auto* a, auto* b) { return a->time_s.size() > b->time_s.size(); });
  if (static_cast<int>(longest.size()) > o.max_player_heatmaps) {
    longest.resize(o.max_player_heatmaps);
  }
  for (const auto* s : longest) {
    Write(fmt::format("{}/heatmap_player{}.png", out_dir, s->id),
          HeatMap({s}, field, view, o, "player " + LabelOf(s->id, o.name_of)), files);
    rp.player_maps.push_back(s->id);
  }
  std::sort(rp.player_maps.begin(), rp.player_maps.end());
}

// Radar: whole trajectories; and the video (10 frames per second of play).
void WriteRadar(const field::FieldModel& field, ReportParts& rp, ReportFiles& files) {
  const StatsResult& r = rp.r;
  const StatsOptions& o = rp.o;
  const field::TopView& view = rp.view;
  {
    cv::Mat img = field::DrawField(field, view);
    DrawZones(img, o.zones, view);
    DrawRadar(img, r, view, rp.t1, rp.t1 - rp.t0 + 1, o);
    cv::putText(img, "radar: all trajectories", {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.7,
                {255, 255, 255}, 2);
    Write(rp.out_dir + "/radar.png",
          field::FrameTopView(img, view,
                              "trails: each player's whole track; filled dot: at the end of the "
                              "clip, ring: where a track ended earlier"),
          files);
  }
  if (!o.write_video) return;
  if (!io::H264Available()) {
    files.notes.push_back(
        "radar video skipped: OpenCV's FFmpeg has no H.264 encoder here (a video browsers play)");
    return;
  }
  const std::string path = rp.out_dir + "/radar.mp4";
  cv::Mat base = field::DrawField(field, view);
  DrawZones(base, o.zones, view);
  const std::string caption = "trails: the last 3 s; filled dot: now, ring: where a track ended";
  io::PlayableVideoWriter vw(path, 10.0, field::FrameTopView(base, view, caption).size());
  for (double t = rp.t0; t <= rp.t1; t += 0.1) {
    cv::Mat img = base.clone();
    DrawRadar(img, r, view, t, 3.0, o);
    cv::putText(img, fmt::format("t = {:.1f} s", t), {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.7,
                {255, 255, 255}, 2);
    vw.Write(field::FrameTopView(img, view, caption));
  }
  vw.Close();
  files.files.push_back(path);
  rp.radar_video = "radar.mp4";
}

// distances.csv, players.csv and speed_profiles.csv.
void WriteTables(const ReportParts& rp, ReportFiles& files) {
  const StatsResult& r = rp.r;
  const StatsOptions& o = rp.o;
  const std::string& out_dir = rp.out_dir;
  // Distances between players.
  {
    const std::string path = out_dir + "/distances.csv";
    util::CsvWriter w(path, {"time_s", "id_a", "id_b", "distance_m"}, 3);
    for (const auto& [t, a, b, d] : r.pair_distances) {
      w << t << a << b << d;
      w.EndRow();
    }
    w.Close();
    files.files.push_back(path);
  }
  // The players' table as CSV (and the speed profiles, one row per player and second).
  {
    const std::string path = out_dir + "/players.csv";
    std::vector<std::string> header = {
        "id",        "name",       "team",          "from_s",         "to_s",
        "tracked_s", "distance_m", "top_speed_mps", "mean_speed_mps", "sprints"};
    for (const auto& b : rp.band_names) header.push_back("time_" + b + "_mps_s");
    for (const auto& z : o.zones) header.push_back("time_in_" + z.name + "_s");
    util::CsvWriter w(path, header, 2);
    for (const auto& p : r.players) {
      w << p.id << p.name << p.team << p.first_s << p.last_s << p.tracked_s << p.distance_m
        << p.top_speed_mps << p.mean_speed_mps << p.sprints;
      for (double bt : p.band_time_s) w << bt;
      for (const auto& z : o.zones) w << p.zone_time_s.at(z.name);
      w.EndRow();
    }
    w.Close();
    files.files.push_back(path);
  }
  {
    const std::string path = out_dir + "/speed_profiles.csv";
    util::CsvWriter w(path, {"id", "time_s", "speed_mps"}, 2);
    for (const auto& p : r.players) {
      for (const auto& [t, v] : p.speed_profile) {
        w << p.id << t << v;
        w.EndRow();
      }
    }
    w.Close();
    files.files.push_back(path);
  }
}

nlohmann::json StatsJson(const StatsResult& r, const StatsOptions& o, const ReportFiles& files) {
  nlohmann::json j;
  j["duration_s"] = r.duration_s;
  j["fps"] = util::JsonRound(r.fps, 6);  // from time_s steps (10.000000000000036)
  j["time_source"] = r.time_source;
  j["summary"] = r.Summary();
  j["speed_bands_mps"] = o.speed_bands_mps;
  j["players"] = nlohmann::json::array();
  for (const auto& p : r.players) {
    nlohmann::json pj = {{"id", p.id},
                         {"name", p.name},
                         {"team", p.team},
                         {"first_s", p.first_s},
                         {"last_s", p.last_s},
                         {"tracked_s", p.tracked_s},
                         {"distance_m", p.distance_m},
                         {"top_speed_mps", p.top_speed_mps},
                         {"mean_speed_mps", p.mean_speed_mps},
                         {"position_noise_m", p.position_noise_m},
                         {"sprints", p.sprints},
                         {"band_time_s", p.band_time_s},
                         {"zone_time_s", p.zone_time_s}};
    nlohmann::json prof = nlohmann::json::array();
    for (const auto& [t, v] : p.speed_profile) prof.push_back({t, v});
    pj["speed_profile"] = prof;
    j["players"].push_back(pj);
  }
  j["zone_events"] = nlohmann::json::array();
  for (const auto& e : r.events) {
    j["zone_events"].push_back(
        {{"zone", e.zone}, {"id", e.id}, {"enter_s", e.enter_s}, {"exit_s", e.exit_s}});
  }
  j["files"] = files.files;
  j["notes"] = files.notes;
  return j;
}

// index.html: one folder that stands alone (images, CSVs and the video beside it).
void WriteIndexHtml(const std::string& path, const ReportParts& rp, const ReportFiles& files) {
  const StatsResult& r = rp.r;
  const StatsOptions& o = rp.o;
  std::ostringstream h;
  h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>fieldvision stats</title>"
       "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
       "td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}th{background:#eee}"
       "img,video{max-width:100%}.maps img{width:340px;margin:4px}"
       ".charts div{display:inline-block;margin:4px 12px 4px 0}</style></head><body>\n";
  h << "<h1>Player statistics</h1>\n<p>" << Html(r.Summary()) << "</p>\n";
  for (const auto& n : files.notes) h << "<p><em>" << Html(n) << "</em></p>\n";
  h << "<h2>Players</h2>\n<p>Click a column header to sort. Download: <a href=\"players.csv\">"
       "players.csv</a>, <a href=\"speed_profiles.csv\">speed_profiles.csv</a> (speed per "
       "player and second), <a href=\"distances.csv\">distances.csv</a> (distances between "
       "players each second), <a href=\"stats.json\">stats.json</a>.</p>\n";
  h << "<table class=\"sortable\"><tr><th>id</th><th>name</th><th>team</th><th>from s</th>"
       "<th>to s</th><th>tracked s</th><th>distance m</th><th>top speed m/s</th>"
       "<th>mean speed m/s</th><th>sprints</th>";
  for (const auto& b : rp.band_names) h << "<th>" << b << " m/s (s)</th>";
  for (const auto& z : o.zones) h << "<th>in " << Html(z.name) << " (s)</th>";
  h << "</tr>\n";
  for (const auto& p : r.players) {
    h << fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.1f}</td><td>{:.1f}</td><td>{:.1f}</td>"
        "<td>{:.1f}</td><td>{:.2f}</td><td>{:.2f}</td><td>{}</td>",
        p.id, Html(p.name), p.team >= 0 ? std::to_string(p.team) : "-", p.first_s, p.last_s,
        p.tracked_s, p.distance_m, p.top_speed_mps, p.mean_speed_mps, p.sprints);
    for (double bt : p.band_time_s) h << fmt::format("<td>{:.1f}</td>", bt);
    for (const auto& z : o.zones) h << fmt::format("<td>{:.1f}</td>", p.zone_time_s.at(z.name));
    h << "</tr>\n";
  }
  h << "</table>\n";
  // Speed over time: one chart per player, same axes for all.
  double vmax = o.sprint_speed_mps;
  for (const auto& p : r.players) {
    for (const auto& [t, v] : p.speed_profile) vmax = std::max(vmax, v);
  }
  vmax = std::ceil(vmax + 0.5);
  h << "<h2>Speed over time</h2>\n<p>Mean speed per second (m/s); the dashed red line is the "
       "sprint threshold ("
    << fmt::format("{:g}", o.sprint_speed_mps) << " m/s).</p>\n<div class=\"charts\">";
  for (const auto& p : r.players) {
    h << "<div><b>"
      << Html(p.name.empty() ? "player " + std::to_string(p.id)
                             : p.name + " (" + std::to_string(p.id) + ")")
      << "</b><br>" << SpeedChartSvg(p, rp.t0, rp.t1, vmax, o.sprint_speed_mps) << "</div>";
  }
  h << "</div>\n";
  if (!o.zones.empty()) {
    h << "<h2>Zone alerts</h2>\n<table class=\"sortable\"><tr><th>zone</th><th>id</th>"
         "<th>entered s</th><th>left s</th></tr>\n";
    for (const auto& e : r.events) {
      h << fmt::format("<tr><td>{}</td><td>{}</td><td>{:.1f}</td><td>{:.1f}</td></tr>\n",
                       Html(e.zone), e.id, e.enter_s, e.exit_s);
    }
    h << "</table>\n";
  }
  h << "<h2>Radar view</h2>\n<p><img src=\"radar.png\"></p>\n";
  if (!rp.radar_video.empty()) {
    h << "<p><video src=\"" << rp.radar_video << "\" controls muted playsinline width=\""
      << rp.view.size.width << "\"></video></p>\n";
  }
  h << "<h2>Heat maps</h2>\n<p>Time spent per square metre of field (seconds; the scale's top "
       "is the 99th percentile of the cells, busier cells share its colour). Zones in "
       "yellow.</p>\n<div class=\"maps\"><img src=\"heatmap_all.png\">";
  for (int team : rp.teams) h << fmt::format("<img src=\"heatmap_team{}.png\">", team);
  h << "</div>\n<h3>Per player</h3>\n<div class=\"maps\">";
  for (int id : rp.player_maps) h << fmt::format("<img src=\"heatmap_player{}.png\">", id);
  h << "</div>\n" << kSortScript << "</body></html>\n";
  util::WriteTextFile(path, h.str(), "report page");
}

}  // namespace

ReportFiles WriteStatsReport(const StatsResult& r, const field::FieldModel& field,
                             const StatsOptions& o, const std::string& out_dir) {
  o.Check();
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  FV_REQUIRE(!ec && fs::is_directory(out_dir), "cannot create output folder '{}'", out_dir);
  ReportFiles files;
  if (!r.left_out.empty()) files.notes.push_back(LeftOutNote(r));
  // Heat maps: every player, over the field and where the positions go beyond it.
  ReportParts rp(r, o, out_dir, ReportView(r, field, o, &files));
  WriteHeatMaps(field, rp, files);
  for (const auto& s : r.tracks) {
    rp.t0 = std::min(rp.t0, s.time_s.front());
    rp.t1 = std::max(rp.t1, s.time_s.back());
  }
  WriteRadar(field, rp, files);
  rp.band_names = BandNames(o);
  WriteTables(rp, files);
  {
    const nlohmann::json j = StatsJson(r, o, files);
    const std::string path = out_dir + "/stats.json";
    util::WriteTextFile(path, j.dump(2) + "\n", "stats file");
    files.files.push_back(path);
  }
  WriteIndexHtml(out_dir + "/index.html", rp, files);
  files.files.push_back(out_dir + "/index.html");
  return files;
}

}  // namespace fv::stats
