// Images, video, JSON and HTML of the statistics (declared in stats.h).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/field/field_draw.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/stats/stats.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"

namespace fv::stats {
namespace fs = std::filesystem;
namespace {

cv::Scalar ColourOf(int id, int team) {
  if (team == 0) return {40, 40, 220};
  if (team == 1) return {220, 120, 30};
  static const cv::Scalar kPalette[] = {
      {230, 25, 75},  {60, 180, 75},  {255, 225, 25}, {0, 130, 200},  {245, 130, 48},
      {145, 30, 180}, {70, 240, 240}, {240, 50, 230}, {210, 245, 60}, {250, 190, 212}};
  return kPalette[std::abs(id) % 10];
}

void Write(const std::string& path, const cv::Mat& img, ReportFiles& files) {
  WriteImage(path, img);
  files.files.push_back(path);
}

// Heat map of positions over the field drawing.
cv::Mat HeatMap(const std::vector<const SmoothTrack*>& tracks, const FieldModel& field,
                const TopView& view, const StatsOptions& o, const std::string& title) {
  cv::Mat acc = cv::Mat::zeros(view.size, CV_32F);
  for (const auto* s : tracks) {
    for (size_t i = 0; i < s->pos_m.size(); ++i) {
      const cv::Point2d px = view.ToPixel(s->pos_m[i]);
      const int x = static_cast<int>(px.x), y = static_cast<int>(px.y);
      if (x >= 0 && y >= 0 && x < acc.cols && y < acc.rows) acc.at<float>(y, x) += 1.0f;
    }
  }
  const double sigma = std::max(1.0, o.heat_sigma_m * view.px_per_m);
  cv::GaussianBlur(acc, acc, cv::Size(), sigma);
  double mx = 0;
  cv::minMaxLoc(acc, nullptr, &mx);
  cv::Mat img = DrawField(field, view);
  if (mx > 0) {
    cv::Mat norm8, colour;
    acc.convertTo(norm8, CV_8U, 255.0 / mx);
    cv::applyColorMap(norm8, colour, cv::COLORMAP_JET);
    cv::Mat alpha;
    acc.convertTo(alpha, CV_32F, 1.0 / mx);
    cv::sqrt(alpha, alpha);
    for (int y = 0; y < img.rows; ++y) {
      for (int x = 0; x < img.cols; ++x) {
        const float a = std::min(0.85f, alpha.at<float>(y, x));
        cv::Vec3b& d = img.at<cv::Vec3b>(y, x);
        const cv::Vec3b c = colour.at<cv::Vec3b>(y, x);
        for (int k = 0; k < 3; ++k) d[k] = cv::saturate_cast<uchar>((1 - a) * d[k] + a * c[k]);
      }
    }
    DrawFieldLines(img, field, view, cv::Scalar(255, 255, 255), 1);
  }
  cv::putText(img, title, {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.7, {255, 255, 255}, 2);
  return img;
}

// The radar (top) view at time t: trails of the last seconds and current positions with ids.
void DrawRadar(cv::Mat& img, const StatsResult& r, const TopView& view, double t, double trail_s,
               const std::map<int, int>& team) {
  for (const auto& s : r.tracks) {
    const auto tm = team.find(s.id);
    const cv::Scalar c = ColourOf(s.id, tm == team.end() ? -1 : tm->second);
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
    if (last && t - s.time_s[last_i] < 0.5) {
      cv::circle(img, *last, 7, c, cv::FILLED, cv::LINE_AA);
      cv::circle(img, *last, 7, {0, 0, 0}, 1, cv::LINE_AA);
      cv::putText(img, std::to_string(s.id), *last + cv::Point2d(8, -8), cv::FONT_HERSHEY_SIMPLEX,
                  0.5, {255, 255, 255}, 1, cv::LINE_AA);
    }
  }
}

}  // namespace

ReportFiles WriteStatsReport(const StatsResult& r, const FieldModel& field, const StatsOptions& o,
                             const std::string& out_dir) {
  o.Check();
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  FV_REQUIRE(!ec && fs::is_directory(out_dir), "cannot create output folder '{}'", out_dir);
  ReportFiles files;
  // Heat maps: every player and the extent of all positions beyond the field.
  const TopView view = TopView::ForField(field, o.image_width_px, 2.0);
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
  }
  std::vector<const SmoothTrack*> longest = all;
  std::sort(longest.begin(), longest.end(),
            [](auto* a, auto* b) { return a->time_s.size() > b->time_s.size(); });
  if (static_cast<int>(longest.size()) > o.max_player_heatmaps) {
    longest.resize(o.max_player_heatmaps);
  }
  std::vector<int> player_maps;
  for (const auto* s : longest) {
    Write(fmt::format("{}/heatmap_player{}.png", out_dir, s->id),
          HeatMap({s}, field, view, o, fmt::format("player {}", s->id)), files);
    player_maps.push_back(s->id);
  }
  std::sort(player_maps.begin(), player_maps.end());
  // Radar: whole trajectories; and the video (5 frames per second of play).
  double t0 = 1e300, t1 = -1e300;
  for (const auto& s : r.tracks) {
    t0 = std::min(t0, s.time_s.front());
    t1 = std::max(t1, s.time_s.back());
  }
  {
    cv::Mat img = DrawField(field, view);
    DrawRadar(img, r, view, t1, t1 - t0 + 1, o.team_of);
    cv::putText(img, "radar: all trajectories", {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.7,
                {255, 255, 255}, 2);
    Write(out_dir + "/radar.png", img, files);
  }
  if (o.write_video) {
    const std::string path = out_dir + "/radar.avi";
    const cv::Mat base = DrawField(field, view);
    cv::VideoWriter vw(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, base.size());
    FV_REQUIRE(vw.isOpened(), "cannot write video '{}'", path);
    for (double t = t0; t <= t1; t += 0.1) {
      cv::Mat img = base.clone();
      DrawRadar(img, r, view, t, 3.0, o.team_of);
      cv::putText(img, fmt::format("t = {:.1f} s", t), {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.7,
                  {255, 255, 255}, 2);
      vw.write(img);
    }
    vw.release();
    files.files.push_back(path);
  }
  // Distances between players.
  {
    const std::string path = out_dir + "/distances.csv";
    CsvWriter w(path, {"time_s", "id_a", "id_b", "distance_m"}, 3);
    for (const auto& [t, a, b, d] : r.pair_distances) {
      w << t << a << b << d;
      w.EndRow();
    }
    w.Close();
    files.files.push_back(path);
  }
  // stats.json
  nlohmann::json j;
  j["duration_s"] = r.duration_s;
  j["fps"] = o.fps;
  j["summary"] = r.Summary();
  j["speed_bands_mps"] = o.speed_bands_mps;
  j["players"] = nlohmann::json::array();
  for (const auto& p : r.players) {
    nlohmann::json pj = {{"id", p.id},
                         {"team", p.team},
                         {"first_s", p.first_s},
                         {"last_s", p.last_s},
                         {"distance_m", p.distance_m},
                         {"top_speed_mps", p.top_speed_mps},
                         {"mean_speed_mps", p.mean_speed_mps},
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
  {
    const std::string path = out_dir + "/stats.json";
    std::ofstream out(path);
    FV_REQUIRE(out.good(), "cannot write '{}'", path);
    out << j.dump(2) << "\n";
    files.files.push_back(path);
  }
  // index.html
  {
    const std::string path = out_dir + "/index.html";
    std::ofstream h(path);
    FV_REQUIRE(h.good(), "cannot write '{}'", path);
    h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>fieldvision stats</title>"
         "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
         "td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}img{max-width:100%}"
         ".maps img{width:300px;margin:4px}</style></head><body>\n";
    h << "<h1>Player statistics</h1>\n<p>" << r.Summary() << "</p>\n";
    h << "<h2>Players</h2>\n<table><tr><th>id</th><th>team</th><th>from s</th><th>to s</th>"
         "<th>distance m</th><th>top speed m/s</th><th>mean speed m/s</th><th>sprints</th>";
    for (size_t b = 0; b <= o.speed_bands_mps.size(); ++b) {
      const std::string lo = b == 0 ? "0" : fmt::format("{:g}", o.speed_bands_mps[b - 1]);
      const std::string hi =
          b < o.speed_bands_mps.size() ? fmt::format("{:g}", o.speed_bands_mps[b]) : "+";
      h << "<th>" << lo << "-" << hi << " m/s (s)</th>";
    }
    for (const auto& z : o.zones) h << "<th>in " << z.name << " (s)</th>";
    h << "</tr>\n";
    for (const auto& p : r.players) {
      h << fmt::format(
          "<tr><td>{}</td><td>{}</td><td>{:.1f}</td><td>{:.1f}</td><td>{:.1f}</td><td>{:.2f}"
          "</td><td>{:.2f}</td><td>{}</td>",
          p.id, p.team >= 0 ? std::to_string(p.team) : "-", p.first_s, p.last_s, p.distance_m,
          p.top_speed_mps, p.mean_speed_mps, p.sprints);
      for (double bt : p.band_time_s) h << fmt::format("<td>{:.1f}</td>", bt);
      for (const auto& z : o.zones) h << fmt::format("<td>{:.1f}</td>", p.zone_time_s.at(z.name));
      h << "</tr>\n";
    }
    h << "</table>\n";
    if (!o.zones.empty()) {
      h << "<h2>Zone alerts</h2>\n<table><tr><th>zone</th><th>id</th><th>entered s</th>"
           "<th>left s</th></tr>\n";
      for (const auto& e : r.events) {
        h << fmt::format("<tr><td>{}</td><td>{}</td><td>{:.1f}</td><td>{:.1f}</td></tr>\n", e.zone,
                         e.id, e.enter_s, e.exit_s);
      }
      h << "</table>\n";
    }
    h << "<h2>Radar view</h2>\n<p><img src=\"radar.png\"></p><p>Video: <a href=\"radar.avi\">"
         "radar.avi</a>. Distances between players each second: <a href=\"distances.csv\">"
         "distances.csv</a>.</p>\n";
    h << "<h2>Heat maps</h2>\n<div class=\"maps\"><img src=\"heatmap_all.png\">";
    for (const auto& [team, ts] : by_team) {
      h << fmt::format("<img src=\"heatmap_team{}.png\">", team);
    }
    h << "</div>\n<h3>Per player</h3>\n<div class=\"maps\">";
    for (int id : player_maps) h << fmt::format("<img src=\"heatmap_player{}.png\">", id);
    h << "</div>\n</body></html>\n";
    files.files.push_back(path);
  }
  return files;
}

}  // namespace fv::stats
