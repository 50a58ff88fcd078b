#include "fieldvision/track/synth_truth.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <utility>

#include <fmt/format.h>

#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"

namespace fv::track {
namespace {

constexpr const char* kHeader = "frame,cam,id,bb_left,bb_top,bb_width,bb_height,visible_fraction";

struct Place {
  double x_m = 0, y_m = 0, time_s = 0;
};

// players.csv beside `path`, by (frame, id); empty when there is none.
std::map<std::pair<long long, long long>, Place> PlacesBeside(const std::string& path) {
  const std::filesystem::path places = std::filesystem::path(path).parent_path() / "players.csv";
  std::map<std::pair<long long, long long>, Place> out;
  if (!std::filesystem::is_regular_file(places)) return out;
  const util::CsvTable t = util::CsvTable::Read(places.string());
  t.Require({"frame", "time_s", "id", "x_m", "y_m"});
  for (size_t i = 0; i < t.rows(); ++i) {
    out[{t.GetInt(i, "frame"), t.GetInt(i, "id")}] = {t.GetDouble(i, "x_m"), t.GetDouble(i, "y_m"),
                                                      t.GetDouble(i, "time_s")};
  }
  return out;
}

}  // namespace

bool IsSynthPeopleTruth(const std::string& path) {
  std::ifstream in(path);
  std::string first;
  if (!std::getline(in, first)) return false;
  if (!first.empty() && first.back() == '\r') first.pop_back();
  return first == kHeader;
}

std::vector<TrackRow> ReadSynthPeopleTruth(const std::string& path, const std::string& cam,
                                           double min_visible) {
  const util::CsvTable t = util::CsvTable::Read(path);
  t.Require(
      {"frame", "cam", "id", "bb_left", "bb_top", "bb_width", "bb_height", "visible_fraction"});
  std::set<std::string> cams;
  for (size_t i = 0; i < t.rows(); ++i) cams.insert(t.Get(i, "cam"));
  std::string chosen = cam;
  if (chosen.empty()) {
    FV_REQUIRE(cams.size() <= 1, "{}: the truth of cameras {}: name one (--gt-cam)", path,
               fmt::join(cams, ", "));
    if (!cams.empty()) chosen = *cams.begin();
  } else {
    FV_REQUIRE(cams.count(chosen) > 0, "{}: no camera '{}' (it has {})", path, chosen,
               fmt::join(cams, ", "));
  }
  const auto places = PlacesBeside(path);
  std::vector<TrackRow> rows;
  for (size_t i = 0; i < t.rows(); ++i) {
    if (t.Get(i, "cam") != chosen) continue;
    const double visible = t.GetDouble(i, "visible_fraction");
    if (visible < min_visible) continue;
    TrackRow r;
    const long long frame = t.GetInt(i, "frame");
    FV_REQUIRE(frame >= 0 && frame < 100000000, "{}: frame {} out of range", t.Where(i), frame);
    r.frame = static_cast<int>(frame) + 1;
    r.id = static_cast<int>(t.GetInt(i, "id"));
    r.box = {t.GetDouble(i, "bb_left"), t.GetDouble(i, "bb_top"), t.GetDouble(i, "bb_width"),
             t.GetDouble(i, "bb_height")};
    FV_REQUIRE(std::isfinite(r.box.x) && std::isfinite(r.box.y) && r.box.width > 0 &&
                   r.box.height > 0 && std::isfinite(r.box.width) && std::isfinite(r.box.height),
               "{}: the box is not finite or has no size", t.Where(i));
    r.visibility = visible;
    const auto place = places.find({frame, r.id});
    if (place != places.end()) {
      r.x_m = place->second.x_m;
      r.y_m = place->second.y_m;
      r.time_s = place->second.time_s;
    }
    rows.push_back(r);
  }
  return rows;
}

}  // namespace fv::track
