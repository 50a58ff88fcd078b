#include "fieldvision/web/studio_api.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <regex>
#include <sstream>
#include <string_view>
#include <type_traits>

#include <fmt/format.h>

#include "fieldvision/calib/extrinsics.h"
#include "fieldvision/calib/intrinsics.h"
#include "fieldvision/calib/lines.h"
#include "fieldvision/camera/camera_io.h"
#include "fieldvision/camera/frame_size.h"
#include "fieldvision/codecs/codecs.h"
#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/colour.h"
#include "fieldvision/detect/colour_learn.h"
#include "fieldvision/field/field.h"
#include "fieldvision/field/field_json.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/recon/trajectory_io.h"
#include "fieldvision/stats/stats.h"
#include "fieldvision/track/edits.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

namespace fv::web {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

std::string OneLine(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
}

// Bytes that are not UTF-8 (from a request's keys or file names) are replaced, never thrown on.
ApiResponse Json(const json& j, int status = 200) {
  return {status, "application/json", j.dump(-1, ' ', false, json::error_handler_t::replace)};
}

ApiResponse ErrorResponse(int status, const std::string& message) {
  return Json({{"error", OneLine(message)}}, status);
}

double Round(double v, double step = 1e-4) { return std::round(v / step) * step; }

// ---- request helpers

const std::string& Param(const ApiRequest& r, const std::string& name) {
  auto it = r.params.find(name);
  if (it == r.params.end() || it->second.empty()) {
    throw HttpError(400, "missing query parameter '" + name + "'");
  }
  return it->second;
}

json Body(const ApiRequest& r) {
  if (r.body.empty()) throw HttpError(400, "request body is empty (expected JSON)");
  if (util::JsonNestingDepth(r.body) > util::kMaxJsonDepth) {
    throw HttpError(400, fmt::format("request body nests arrays or objects deeper than {} levels",
                                     util::kMaxJsonDepth));
  }
  try {
    json j = json::parse(r.body);
    if (!j.is_object()) throw HttpError(400, "request body is not a JSON object");
    return j;
  } catch (const json::exception& e) {  // a syntax error, a number too large for a double
    throw HttpError(400, "malformed JSON: " + util::JsonErrorText(e));
  }
}

template <typename T>
struct IsIntegerVector : std::false_type {};
template <typename I>
struct IsIntegerVector<std::vector<I>>
    : std::bool_constant<std::is_integral_v<I> && !std::is_same_v<I, bool>> {};

template <typename T>
T Get(const json& body, const std::string& key) {
  if (!body.contains(key)) throw HttpError(400, "missing key '" + key + "'");
  // nlohmann converts 3.7 to 3 and 1e300 to whatever the cast gives.
  const auto require_integer = [&](const json& v, auto type) {
    using I = decltype(type);
    const bool in_range = v.is_number_unsigned()  ? std::in_range<I>(v.get<uint64_t>())
                          : v.is_number_integer() ? std::in_range<I>(v.get<int64_t>())
                                                  : false;
    if (!in_range) throw HttpError(400, "key '" + key + "' must hold integers in range");
  };
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    require_integer(body.at(key), T{});
  } else if constexpr (IsIntegerVector<T>::value) {
    if (!body.at(key).is_array()) throw HttpError(400, "key '" + key + "' must be an array");
    for (const json& v : body.at(key)) require_integer(v, typename T::value_type{});
  }
  try {
    return body.at(key).get<T>();
  } catch (const json::exception&) {
    throw HttpError(400, "key '" + key + "' has the wrong type");
  }
}

template <typename T>
T GetOr(const json& body, const std::string& key, const T& fallback) {
  if (!body.contains(key) || body.at(key).is_null()) return fallback;
  return Get<T>(body, key);
}

int ParseInt(const std::string& text, const std::string& what) {
  try {
    size_t used = 0;
    const int v = std::stoi(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw HttpError(400, what + " '" + text + "' is not an integer");
}

// ---- library adapters

field::FieldModel LoadFieldIn(const Workspace& ws, const std::string& name_or_path) {
  for (const auto& n : field::BuiltinFieldNames()) {
    if (n == name_or_path) return field::BuiltinField(n);
  }
  if (name_or_path.size() < 5 || name_or_path.substr(name_or_path.size() - 5) != ".json") {
    std::string names;
    for (const auto& n : field::BuiltinFieldNames()) names += (names.empty() ? "" : ", ") + n;
    throw HttpError(
        404, "unknown field '" + name_or_path + "' (built in: " + names + ", or a .json file)");
  }
  return field::LoadField(ws.Resolve(name_or_path).string());
}

// The built-in fields' names, then the folder's field files (JSON files of at most 1 MB that read
// as a field; others, flights or zones, are left out).
json FieldsIn(const Workspace& ws) {
  json names = field::BuiltinFieldNames();
  for (const auto& f : ws.ListFiles()) {
    if (f["kind"] != "json" || f["size"].get<uint64_t>() > (1u << 20)) continue;
    try {
      field::LoadField(ws.Resolve(f["path"].get<std::string>()).string());
      names.push_back(f["path"]);
    } catch (const std::exception&) {  // not a field file
    }
  }
  return names;
}

// The image's border through the lens model, in normalized coordinates (x/z, y/z): 8 points a side
// from the top-left corner round, so that a client tells whether the camera's image holds a point
// (a pinhole's frame would leave out what a barrel or fisheye lens bends into it). Points whose
// undistortion does not converge are left out.
json ImageOutlineNormalized(const camera::Camera& c) {
  constexpr int kPerSide = 8;
  const double x0 = -0.5, y0 = -0.5, x1 = c.width - 0.5, y1 = c.height - 0.5;
  const std::array<Eigen::Vector2d, 5> corners = {Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y0),
                                                  Eigen::Vector2d(x1, y1), Eigen::Vector2d(x0, y1),
                                                  Eigen::Vector2d(x0, y0)};
  json outline = json::array();
  for (int side = 0; side < 4; ++side) {
    for (int k = 0; k < kPerSide; ++k) {
      const double f = static_cast<double>(k) / kPerSide;
      const Eigen::Vector2d uv = (1.0 - f) * corners[side] + f * corners[side + 1];
      if (const auto xn = c.Undistort(uv); xn && xn->allFinite()) {
        outline.push_back({xn->x(), xn->y()});
      }
    }
  }
  return outline;
}

json CameraToJson(const camera::Camera& c) {
  json j = {{"name", c.name},
            {"width", c.width},
            {"height", c.height},
            {"fx", c.fx},
            {"fy", c.fy},
            {"cx", c.cx},
            {"cy", c.cy},
            {"distortion", c.distortion},
            {"has_pose", c.has_pose}};
  if (c.rms_px) j["rms_px"] = *c.rms_px;
  if (c.has_pose) {
    j["rvec"] = util::JsonFromVector(c.cam_from_world.Rvec());
    j["tvec"] = util::JsonFromVector(c.cam_from_world.translation);
    j["position_m"] = util::JsonFromVector(c.CentreInWorld());
    const Eigen::Matrix3d& r = c.cam_from_world.rotation;
    j["cam_from_world_rotation"] = {r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1),
                                    r(1, 2), r(2, 0), r(2, 1), r(2, 2)};
  }
  j["image_outline_normalized"] = ImageOutlineNormalized(c);
  return j;
}

// Field lines and keypoints as the camera sees them: polylines in pixels (split where a point is
// behind the camera or far outside the image).
json ProjectField(const camera::Camera& cam, const field::FieldModel& field) {
  json lines = json::array();
  const double margin = 0.5 * std::max(cam.width, cam.height);
  auto add_polyline = [&](const std::function<Eigen::Vector2d(double)>& at, double length_m) {
    const int n = std::max(2, int(std::ceil(length_m / 0.2)) + 1);
    json poly = json::array();
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d p = at(double(i) / (n - 1));
      const auto uv = cam.Project(Eigen::Vector3d(p.x(), p.y(), 0.0));
      if (uv && cam.InImage(*uv, -margin)) {
        poly.push_back({Round(uv->x(), 0.01), Round(uv->y(), 0.01)});
      } else {
        if (poly.size() >= 2) lines.push_back(poly);
        poly = json::array();
      }
    }
    if (poly.size() >= 2) lines.push_back(poly);
  };
  for (const auto& s : field.segments) {
    add_polyline([&](double t) { return Eigen::Vector2d(s.a + t * (s.b - s.a)); },
                 (s.b - s.a).norm());
  }
  for (const auto& a : field.arcs) {
    add_polyline(
        [&](double t) {
          const double ang = a.start_rad + t * (a.end_rad - a.start_rad);
          return Eigen::Vector2d(a.centre +
                                 a.radius_m * Eigen::Vector2d(std::cos(ang), std::sin(ang)));
        },
        a.radius_m * (a.end_rad - a.start_rad));
  }
  json keypoints = json::array();
  for (const auto& k : field.keypoints) {
    const auto uv = cam.Project(k.position_m);
    if (uv && cam.InImage(*uv)) {
      keypoints.push_back(
          {{"name", k.name}, {"u", Round(uv->x(), 1e-3)}, {"v", Round(uv->y(), 1e-3)}});
    }
  }
  return {{"lines_px", lines}, {"keypoints_px", keypoints}};
}

std::vector<calib::PointCorrespondence> ParseClicks(const json& body,
                                                    const field::FieldModel& field) {
  if (!body.contains("points") || !body["points"].is_array()) {
    throw HttpError(400, "missing key 'points' (an array of {name, u, v})");
  }
  std::vector<calib::PointCorrespondence> points;
  int i = 0;
  for (const auto& p : body["points"]) {
    const std::string where = "points[" + std::to_string(i++) + "]";
    if (!p.is_object() || !p.contains("u") || !p.contains("v") || !p["u"].is_number() ||
        !p["v"].is_number()) {
      throw HttpError(400, where + " needs numbers u and v");
    }
    calib::PointCorrespondence c;
    c.uv_px = {p["u"].get<double>(), p["v"].get<double>()};
    if (p.contains("name") && p["name"].is_string()) {
      c.name = p["name"].get<std::string>();
      const field::FieldKeypoint* k = field.FindKeypoint(c.name);
      if (!k) throw HttpError(400, where + ": '" + c.name + "' is not a keypoint of " + field.name);
      c.p_world = k->position_m;
    } else if (p.contains("x") && p.contains("y")) {
      c.name = where;
      c.p_world = {p["x"].get<double>(), p["y"].get<double>(), p.value("z", 0.0)};
    } else {
      throw HttpError(400, where + " needs a keypoint name or x, y (metres)");
    }
    points.push_back(c);
  }
  return points;
}

json PoseToJson(const calib::ExtrinsicsResult& r, const field::FieldModel& field) {
  json points = json::array();
  for (const auto& p : r.points) {
    json j = {{"name", p.name},
              {"u", p.uv_px.x()},
              {"v", p.uv_px.y()},
              {"projected", {Round(p.projected_px.x(), 1e-3), Round(p.projected_px.y(), 1e-3)}},
              {"err_px", Round(p.err_px)},
              {"inlier", p.inlier}};
    j["err_mm"] = p.err_mm ? json(Round(*p.err_mm, 0.01)) : json(nullptr);
    points.push_back(j);
  }
  json j = {{"camera", CameraToJson(r.camera)},
            {"points", points},
            {"num_inliers", r.num_inliers},
            {"rms_px", Round(r.rms_px)},
            {"max_err_px", Round(r.max_err_px)},
            {"mean_err_mm", Round(r.mean_err_mm, 0.01)},
            {"max_err_mm", Round(r.max_err_mm, 0.01)},
            {"camera_position_m", util::JsonFromVector(r.camera_position_m)},
            {"summary", OneLine(r.Summary())}};
  j.update(ProjectField(r.camera, field));
  return j;
}

json LineStatsToJson(const calib::LineErrorStats& s) {
  return {{"num_pixels", s.num_pixels},        {"num_inliers", s.num_inliers},
          {"mean_mm", Round(s.mean_mm, 0.01)}, {"median_mm", Round(s.median_mm, 0.01)},
          {"p95_mm", Round(s.p95_mm, 0.01)},   {"summary", OneLine(s.Summary())}};
}

// An image set for intrinsics (folder, glob in the file name, one image or a video) inside the
// working folder; every file it lists must be inside too (links followed).
std::string ResolveImageSpec(const Workspace& ws, const std::string& spec) {
  if (spec.find_first_of("*?[") == std::string::npos) return ws.Resolve(spec).string();
  const fs::path p(spec);
  const std::string dir = p.parent_path().string();
  if (dir.find_first_of("*?[") != std::string::npos) {
    throw HttpError(400, "images '" + spec + "': wildcards are allowed in the file name only");
  }
  return (ws.Resolve(dir.empty() ? "." : dir) / p.filename()).string();
}

// The file name relative to the working folder ("dir/left01.jpg", "video.avi#12").
std::string RelativeName(const Workspace& ws, const std::string& name) {
  const std::string root = ws.root().string() + "/";
  return name.rfind(root, 0) == 0 ? name.substr(root.size()) : name;
}

calib::BoardSpec BoardFromJson(const json& j) {
  if (!j.is_object()) {
    throw HttpError(400, "'board' must be an object {type, cols, rows, square_m}");
  }
  calib::BoardSpec b;
  b.type = calib::ParseBoardType(GetOr<std::string>(j, "type", "chessboard"));
  b.cols = Get<int>(j, "cols");
  b.rows = Get<int>(j, "rows");
  b.square_m = Get<double>(j, "square_m");
  b.marker_m = GetOr<double>(j, "marker_m", 0.0);
  b.dictionary = GetOr<std::string>(j, "dictionary", b.dictionary);
  try {
    b.Check();
  } catch (const fv::Error& e) {
    throw HttpError(400, e.what());
  }
  return b;
}

json IntrinsicsToJson(const Workspace& ws, const calib::IntrinsicsResult& r) {
  json views = json::array();
  for (const auto& v : r.views) {
    views.push_back({{"name", RelativeName(ws, v.name)},
                     {"board_found", v.board_found},
                     {"num_corners", v.num_corners},
                     {"rms_px", Round(v.rms_px)},
                     {"used", v.used},
                     {"dropped_because", v.dropped_because}});
  }
  return {
      {"camera", CameraToJson(r.camera)},
      {"rms_px", Round(r.rms_px)},
      {"num_images", r.num_images},
      {"num_found", r.num_found},
      {"num_used", r.num_used},
      {"views", views},
      {"std_px", {Round(r.std_fx_px), Round(r.std_fy_px), Round(r.std_cx_px), Round(r.std_cy_px)}},
      {"coverage",
       {{"grid", r.coverage.grid},
        {"corners_per_cell", r.coverage.corners_per_cell},
        {"cell_fraction", Round(r.coverage.cell_fraction)},
        {"radius_fraction", Round(r.coverage.radius_fraction)},
        {"tilt_range_deg", Round(r.coverage.tilt_range_deg, 0.01)}}},
      {"warnings", r.warnings},
      {"summary", OneLine(r.Summary())}};
}

detect::ColourRange RangeFromJson(const json& j) {
  if (!j.is_object() || !j.contains("min") || !j.contains("max")) {
    throw HttpError(400, "'range' needs min and max ([h, s, v])");
  }
  detect::ColourRange r;
  try {
    r.min = j["min"].get<std::array<double, 3>>();
    r.max = j["max"].get<std::array<double, 3>>();
  } catch (const json::exception&) {
    throw HttpError(400, "'range' min and max must be three numbers each");
  }
  if (j.value("space", "hsv") == "yuv") r.space = detect::ColourSpace::kYuv;
  return r;
}

json RangeToJson(const detect::ColourRange& r) {
  return {{"space", r.space == detect::ColourSpace::kHsv ? "hsv" : "yuv"},
          {"min", {Round(r.min[0], 0.01), Round(r.min[1], 0.01), Round(r.min[2], 0.01)}},
          {"max", {Round(r.max[0], 0.01), Round(r.max[1], 0.01), Round(r.max[2], 0.01)}}};
}

// A preset's field and line classes with the ball class replaced by `range`.
detect::ColourSpec SpecWithBallRange(const detect::ColourRange& range) {
  detect::ColourSpec spec = detect::PresetColourSpec("orange");
  const int ball = spec.Find(spec.ball_class);
  spec.classes[ball].ranges = {range};
  spec.Check("studio colour");
  return spec;
}

std::vector<Eigen::Vector2d> ParseUvList(const json& body, const std::string& key) {
  std::vector<Eigen::Vector2d> out;
  if (!body.contains(key)) return out;
  if (!body[key].is_array()) throw HttpError(400, "'" + key + "' must be an array of [u, v]");
  for (const auto& p : body[key]) {
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) {
      throw HttpError(400, "'" + key + "' must be an array of [u, v]");
    }
    out.emplace_back(p[0].get<double>(), p[1].get<double>());
  }
  return out;
}

std::string EncodePng(const cv::Mat& image) {
  std::vector<uchar> buf;
  codecs::ImEncode(".png", image, &buf, {cv::IMWRITE_PNG_COMPRESSION, 1});
  return std::string(buf.begin(), buf.end());
}

// Writes `zones` to `out` after the reader that `stats --zones` uses has checked them on the
// temporary file (nothing is replaced by zones it would refuse); HttpError 400 naming the problem.
void SaveZones(const json& zones, const fs::path& out) {
  try {
    util::AtomicWrite(
        out.string(),
        [&](const std::string& tmp) {
          std::ofstream file(tmp, std::ios::binary);
          file << zones.dump(1) << "\n";
          file.close();
          FV_REQUIRE(!file.fail(), "cannot write zones file '{}'", out.string());
          stats::ReadZones(tmp);
        },
        "zones file");
  } catch (const HttpError&) {
    throw;
  } catch (const fv::Error& e) {
    // The reader names the file it read; the zones came in the request.
    const std::string named =
        util::ReplaceAll(e.what(), "zones file '" + out.string() + "'", "the zones sent");
    throw HttpError(400, util::ReplaceAll(named, out.string(), "the zones sent"));
  }
}

// Bytes of base64 text (RFC 4648, padding optional, a data: URL's prefix skipped); throws
// HttpError 400 naming `what` on anything else.
std::string DecodeBase64(std::string_view text, const std::string& what) {
  if (text.rfind("data:", 0) == 0) {
    const size_t comma = text.find(',');
    if (comma == std::string_view::npos) {
      throw HttpError(400, what + " is a data: URL without data");
    }
    text.remove_prefix(comma + 1);
  }
  std::string out;
  out.reserve(text.size() / 4 * 3 + 3);
  uint32_t acc = 0;
  int bits = 0;
  int pad = 0;
  for (const char c : text) {
    int v = -1;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    if (c >= '0' && c <= '9') v = c - '0' + 52;
    if (c == '+') v = 62;
    if (c == '/') v = 63;
    if (c == '=') {
      ++pad;
      continue;
    }
    if (v < 0 || pad > 0) throw HttpError(400, what + " is not base64 text");
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((acc >> bits) & 0xff));
    }
  }
  if (bits >= 6 || pad > 2) throw HttpError(400, what + " is not base64 text");
  return out;
}

// A PNG image sent as base64 (a canvas's toDataURL()), decoded: refuses anything else.
cv::Mat DecodePngImage(const std::string& base64, const std::string& what) {
  const std::string bytes = DecodeBase64(base64, what);
  static const std::string kSignature = "\x89PNG\r\n\x1a\n";
  if (bytes.compare(0, kSignature.size(), kSignature) != 0) {
    throw HttpError(400, what + " is not a PNG image");
  }
  // The size from the header (IHDR: width, height big-endian at bytes 16..23), before decoding:
  // a 250 KB file may say 16000 x 16000 pixels (1 GB decoded).
  constexpr size_t kIhdrEnd = 24;
  constexpr uint64_t kMaxSidePx = 16384, kMaxPixels = 40'000'000;
  if (bytes.size() < kIhdrEnd) throw HttpError(400, what + " is not a readable PNG image");
  const auto be32 = [&](size_t at) {
    uint64_t v = 0;
    for (size_t k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
    return v;
  };
  const uint64_t w = be32(16), h = be32(20);
  if (w == 0 || h == 0 || w > kMaxSidePx || h > kMaxSidePx || w * h > kMaxPixels) {
    throw HttpError(400, fmt::format("{} is {}x{} pixels: at most {} a side and {} million in all",
                                     what, w, h, kMaxSidePx, kMaxPixels / 1'000'000));
  }
  const std::vector<uchar> buf(bytes.begin(), bytes.end());
  cv::Mat image = codecs::ImDecode(buf, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw HttpError(400, what + " is not a readable PNG image");
  return image;
}

// A folder to write into, named by a request: inside the working folder, not the folder itself,
// its parent existing; it may exist (as a folder) or not.
fs::path ResolveOutputFolder(const Workspace& ws, const std::string& path) {
  fs::path c = ws.Resolve(path, false);
  if (c == ws.root()) throw HttpError(400, "output folder '" + path + "' is the studio folder");
  if (!fs::is_directory(c.parent_path())) {
    throw HttpError(404, "folder of output '" + path + "' does not exist");
  }
  if (fs::exists(c) && !fs::is_directory(c)) {
    throw HttpError(400, "output '" + path + "' is a file, not a folder");
  }
  return c;
}

// ---- endpoints

using Handler = std::function<ApiResponse(const Workspace&, EventHub*, JobRunner*, LiveFeed*,
                                          const ApiRequest&)>;

struct Route {
  Endpoint endpoint;
  Handler handler;
};

// The file a save writes (body[key]): refused (409) when it exists, unless the request says
// replace (the page asks first): a click never replaces a user's camera or colour file.
fs::path SaveTarget(const Workspace& ws, const json& body, const char* key,
                    const std::vector<std::string>& extensions) {
  const std::string name = Get<std::string>(body, key);
  fs::path out = ws.ResolveOutput(name, extensions);
  std::error_code ec;
  if (fs::exists(fs::symlink_status(out, ec)) && !GetOr<bool>(body, "replace", false)) {
    throw HttpError(409,
                    "'" + name + "' exists: choose another name, or replace it (replace: true)");
  }
  return out;
}

// A new folder beside `path` (".NAME.WHAT-XXXXXXXX", never one that was there before); empty
// when none could be made.
fs::path NewFolderBeside(const fs::path& path, const std::string& what) {
  std::error_code ec;
  std::random_device random;
  for (int attempt = 0; attempt < 100; ++attempt) {
    fs::path p =
        path.parent_path() / fmt::format(".{}.{}-{:08x}", path.filename().string(), what, random());
    if (fs::create_directory(p, ec)) return p;
  }
  return {};
}

void Saved(EventHub* events, const Workspace& ws, const fs::path& path, const std::string& what) {
  if (events) events->Publish("saved", {{"path", ws.Relative(path)}, {"what", what}});
}

// Endpoints of the working folder: files, fields, videos, frames, cameras.
std::vector<Route> FolderRoutes() {
  return {
      {{"GET", "/api/endpoints", "this list"},
       [](const Workspace&, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest&) {
         json j = json::array();
         for (const auto& e : StudioApi::Endpoints()) {
           j.push_back({{"method", e.method}, {"path", e.path}, {"summary", e.summary}});
         }
         return Json(j);
       }},
      {{"GET", "/api/info",
        "working folder, fields (built in, then the folder's field files) and "
        "colour presets"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest&) {
         return Json({{"root", ws.root().string()},
                      {"fields", FieldsIn(ws)},
                      {"colour_presets", detect::ColourPresetNames()}});
       }},
      {{"GET", "/api/files", "files of the working folder: [{path, size, kind}]"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest&) {
         return Json(ws.ListFiles());
       }},
      {{"GET", "/api/field", "?name=NAME_OR_JSON: the field model (field show --json)"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         return Json(field::FieldToJson(LoadFieldIn(ws, Param(r, "name"))));
       }},
      {{"GET", "/api/video", "?path=V: width, height, frames, fps"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const fs::path p = ws.Resolve(Param(r, "path"));
         auto source = io::VideoSource::Open(p.string());
         return Json({{"path", ws.Relative(p)},
                      {"width", source->width()},
                      {"height", source->height()},
                      {"frames", source->frame_count()},
                      {"fps", source->fps()}});
       }},
      {{"GET", "/api/frame", "?path=V&frame=N: frame N of a video or image pattern (PNG)"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const fs::path p = ws.Resolve(Param(r, "path"));
         const int frame = r.params.count("frame") ? ParseInt(r.params.at("frame"), "frame") : 0;
         if (frame < 0) throw HttpError(400, "frame must be >= 0");
         const cv::Mat bgr = detect::ReadVideoFrame(p.string(), frame);
         return ApiResponse{200, "image/png", EncodePng(bgr)};
       }},
      {{"GET", "/api/camera", "?path=CAM.yaml: the camera (intrinsics, pose, position)"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         return Json(CameraToJson(camera::ReadCameraYaml(ws.Resolve(Param(r, "path")).string())));
       }},
  };
}

// Endpoints of calibration by hand: projection, pose, saving, line refinement.
std::vector<Route> CalibrationRoutes() {
  return {
      {{"POST", "/api/calibrate/project",
        "{camera, field}: the field's lines and keypoints in the camera's image"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const json body = Body(r);
         const camera::Camera cam =
             camera::ReadCameraYaml(ws.Resolve(Get<std::string>(body, "camera")).string());
         if (!cam.has_pose) throw HttpError(422, "camera file has no pose (rvec, tvec)");
         return Json(ProjectField(cam, LoadFieldIn(ws, Get<std::string>(body, "field"))));
       }},
      {{"POST", "/api/calibrate/pose",
        "{camera, field, points: [{name, u, v}]}: pose, residuals (px, mm), reprojected lines"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const json body = Body(r);
         const camera::Camera cam =
             camera::ReadCameraYaml(ws.Resolve(Get<std::string>(body, "camera")).string());
         const field::FieldModel field = LoadFieldIn(ws, Get<std::string>(body, "field"));
         const auto points = ParseClicks(body, field);
         return Json(PoseToJson(calib::EstimatePose(cam, points), field));
       }},
      {{"POST", "/api/calibrate/save",
        "{camera, field, points, out[, points_out]}: estimate the pose and write the camera file"},
       [](const Workspace& ws, EventHub* events, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const json body = Body(r);
         const camera::Camera cam =
             camera::ReadCameraYaml(ws.Resolve(Get<std::string>(body, "camera")).string());
         const field::FieldModel field = LoadFieldIn(ws, Get<std::string>(body, "field"));
         const auto points = ParseClicks(body, field);
         const fs::path out = SaveTarget(ws, body, "out", {".yaml", ".yml"});
         fs::path points_out;
         if (body.contains("points_out")) {
           points_out = SaveTarget(ws, body, "points_out", {".csv"});
         }
         const calib::ExtrinsicsResult result = calib::EstimatePose(cam, points);
         camera::WriteCameraYaml(result.camera, out.string());
         json j = PoseToJson(result, field);
         j["wrote"] = {ws.Relative(out)};
         if (!points_out.empty()) {
           std::ostringstream csv;
           csv.precision(10);
           csv << "u,v,name\n";
           for (const auto& p : points) {
             csv << p.uv_px.x() << ',' << p.uv_px.y() << ',' << p.name << '\n';
           }
           util::WriteTextFile(points_out.string(), csv.str(), "points file");
           j["wrote"].push_back(ws.Relative(points_out));
         }
         Saved(events, ws, out, "camera");
         return Json(j);
       }},
      {{"POST", "/api/calibrate/refine",
        "{camera, field, video, frame[, points][, out]}: the pose (from the points, else the "
        "camera file's) refined against the painted lines of the frame; line errors before and "
        "after, the line pixels; writes the refined camera when out is given and it is accepted"},
       [](const Workspace& ws, EventHub* events, JobRunner*, LiveFeed*, const ApiRequest& r) {
         const json body = Body(r);
         const std::string camera_path = Get<std::string>(body, "camera");
         camera::Camera cam = camera::ReadCameraYaml(ws.Resolve(camera_path).string());
         const field::FieldModel field = LoadFieldIn(ws, Get<std::string>(body, "field"));
         const std::string video_path = Get<std::string>(body, "video");
         const fs::path video = ws.Resolve(video_path);
         fs::path out;
         if (body.contains("out")) {
           out = SaveTarget(ws, body, "out", {".yaml", ".yml"});
         }
         if (body.contains("points")) {
           cam = calib::EstimatePose(cam, ParseClicks(body, field)).camera;
         }
         if (!cam.has_pose) {
           throw HttpError(422,
                           "no pose to refine: click 4 or more keypoints (or give a camera "
                           "file with a pose)");
         }
         const int frame = GetOr<int>(body, "frame", 0);
         if (frame < 0) throw HttpError(400, "frame must be >= 0");
         const cv::Mat bgr = detect::ReadVideoFrame(video.string(), frame);
         // An encoder's cropped padding (camera/frame_size.h) is fitted and noted.
         const std::string size_note =
             camera::FitCameraToFrames(cam, fmt::format("camera file '{}'", camera_path), bgr.cols,
                                       bgr.rows, fmt::format("video '{}'", video_path));
         const calib::RefineOptions options;
         const auto pixels = calib::DetectLinePixels(bgr, cam, field, options.detect);
         const calib::RefineResult res = calib::RefineWithLinePixels(cam, pixels, field, options);
         json line_pixels = json::array();
         const size_t step = std::max<size_t>(1, pixels.size() / 3000);
         for (size_t i = 0; i < pixels.size(); i += step) {
           line_pixels.push_back({Round(pixels[i].x(), 0.1), Round(pixels[i].y(), 0.1)});
         }
         json j = {{"accepted", res.accepted},
                   {"status", res.status},
                   {"before", LineStatsToJson(res.before)},
                   {"after", LineStatsToJson(res.after)},
                   {"num_line_pixels", res.num_line_pixels},
                   {"iterations", res.iterations},
                   {"moved_m", Round(res.moved_m, 1e-5)},
                   {"rotated_deg", Round(res.rotated_deg, 1e-5)},
                   {"camera", CameraToJson(res.camera)},
                   {"camera_position_m", util::JsonFromVector(res.camera.CentreInWorld())},
                   {"line_pixels", line_pixels},
                   {"summary", OneLine(res.Summary())},
                   {"wrote", json::array()}};
         j.update(ProjectField(res.camera, field));
         if (!size_note.empty()) j["note"] = size_note;
         if (!out.empty() && res.accepted) {
           camera::WriteCameraYaml(res.camera, out.string());
           j["wrote"].push_back(ws.Relative(out));
           Saved(events, ws, out, "camera");
         }
         return Json(j);
       }},
  };
}

// Endpoints of intrinsics from boards and the live feed.
std::vector<Route> IntrinsicsAndLiveRoutes() {
  return {
      {{"POST", "/api/calibrate/intrinsics",
        "{images: FOLDER|GLOB|IMAGE|VIDEO, board: {type, cols, rows, square_m[, marker_m, "
        "dictionary]}[, num_distortion, k3 (auto|free|zero), fix_aspect_ratio, zero_tangent, name, "
        "out]}: intrinsics "
        "from board images with per-view errors; writes the camera file when out is given"},
       [](const Workspace& ws, EventHub* events, JobRunner*, LiveFeed*, const ApiRequest& r) {
         const json body = Body(r);
         calib::IntrinsicsOptions o;
         o.board = BoardFromJson(Get<json>(body, "board"));
         o.num_distortion = GetOr<int>(body, "num_distortion", o.num_distortion);
         o.fix_aspect_ratio = GetOr<bool>(body, "fix_aspect_ratio", false);
         o.zero_tangent = GetOr<bool>(body, "zero_tangent", false);
         o.camera_name = GetOr<std::string>(body, "name", "");
         o.progress = false;
         try {
           o.k3 = calib::ParseK3Model(GetOr<std::string>(body, "k3", "auto"));
           o.Check();
         } catch (const fv::Error& e) {
           throw HttpError(400, e.what());
         }
         const std::string spec = ResolveImageSpec(ws, Get<std::string>(body, "images"));
         // Every listed file must be inside the folder (a link may point elsewhere).
         const calib::ImageSource source(spec, o.source);
         if (source.size() > 200) throw HttpError(400, "more than 200 images: choose fewer");
         for (int i = 0; i < source.size(); ++i) {
           if (source.name(i).find('#') == std::string::npos) ws.Resolve(source.name(i));
         }
         fs::path out;
         if (body.contains("out")) {
           out = SaveTarget(ws, body, "out", {".yaml", ".yml"});
         }
         const calib::IntrinsicsResult res = calib::CalibrateIntrinsics(spec, o);
         json j = IntrinsicsToJson(ws, res);
         j["wrote"] = json::array();
         if (!out.empty()) {
           camera::WriteCameraYaml(res.camera, out.string());
           j["wrote"].push_back(ws.Relative(out));
           Saved(events, ws, out, "camera");
         }
         return Json(j);
       }},
      {{"POST", "/api/live/start",
        "{endpoint: tcp://HOST:PORT}: subscribe to a fusion node's positions (fuse --publish); "
        "they arrive as 'ball' events on /api/events"},
       [](const Workspace&, EventHub*, JobRunner*, LiveFeed* live, const ApiRequest& r) {
         if (!live) throw HttpError(404, "this server has no live feed");
         live->Start(Get<std::string>(Body(r), "endpoint"));
         return Json(live->Status());
       }},
      {{"POST", "/api/live/stop", "{}: end the subscription"},
       [](const Workspace&, EventHub*, JobRunner*, LiveFeed* live, const ApiRequest& r) {
         if (!live) throw HttpError(404, "this server has no live feed");
         if (!r.body.empty()) Body(r);  // a malformed body is refused like everywhere else
         live->Stop();
         return Json(live->Status());
       }},
      {{"GET", "/api/live", "the live feed: state, endpoint, positions received, last position"},
       [](const Workspace&, EventHub*, JobRunner*, LiveFeed* live, const ApiRequest&) {
         if (!live) throw HttpError(404, "this server has no live feed");
         return Json(live->Status());
       }},
  };
}

// One frame's clicks for colour learning: `j`'s points, roi and negative points (its frame,
// `frame` or 0, is read by the caller); `what` names it in errors.
detect::ColourLearnSample LearnSampleOf(const json& j, const std::string& what) {
  detect::ColourLearnSample sample;
  sample.points = ParseUvList(j, "points");
  sample.negative_points = ParseUvList(j, "negative_points");
  if (j.contains("roi")) {
    const auto roi = Get<std::array<int, 4>>(j, "roi");
    sample.boxes.emplace_back(roi[0], roi[1], roi[2], roi[3]);
  }
  if (sample.points.empty() && sample.boxes.empty()) {
    throw HttpError(400, what + ": give 'points' or 'roi'");
  }
  return sample;
}

// Endpoints of ball colour: learning, saving, detection on a frame.
std::vector<Route> ColourRoutes() {
  return {
      {{"POST", "/api/colour/learn",
        "{video, frame, points: [[u, v]], roi: [x, y, w, h], negative_points} or {video, "
        "samples: [{frame, points, roi, negative_points}]} (clicks on several frames): HSV box"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const json body = Body(r);
         const fs::path video = ws.Resolve(Get<std::string>(body, "video"));
         std::vector<detect::ColourLearnSample> samples;
         std::vector<int> frames;
         if (body.contains("samples")) {
           const json& list = body["samples"];
           if (!list.is_array() || list.empty() || list.size() > 100) {
             throw HttpError(400, "'samples' must be an array of 1 to 100 frames' clicks");
           }
           for (size_t i = 0; i < list.size(); ++i) {
             if (!list[i].is_object()) {
               throw HttpError(400, fmt::format("samples[{}]: not an object", i));
             }
             samples.push_back(LearnSampleOf(list[i], fmt::format("samples[{}]", i)));
             frames.push_back(GetOr<int>(list[i], "frame", 0));
           }
         } else {
           samples.push_back(LearnSampleOf(body, "the request"));
           frames.push_back(GetOr<int>(body, "frame", 0));
         }
         const std::vector<cv::Mat> bgr = detect::ReadVideoFrames(video.string(), frames);
         for (size_t i = 0; i < samples.size(); ++i) samples[i].bgr = bgr[i];
         const detect::ColourLearnResult res = detect::LearnColour(samples, {});
         return Json({{"range", RangeToJson(res.range)},
                      {"positives", res.positives},
                      {"negatives", res.negatives},
                      {"frames", samples.size()},
                      {"recall", Round(res.recall)},
                      {"negative_rate", Round(res.negative_rate, 1e-6)},
                      {"summary", OneLine(res.Summary())}});
       }},
      {{"POST", "/api/colour/save",
        "{range: {min, max}, out}: write a colour file (ball class + field + line)"},
       [](const Workspace& ws, EventHub* events, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const json body = Body(r);
         const detect::ColourSpec spec = SpecWithBallRange(RangeFromJson(Get<json>(body, "range")));
         const fs::path out = SaveTarget(ws, body, "out", {".json"});
         detect::WriteColourSpec(spec, out.string());
         Saved(events, ws, out, "colour");
         return Json({{"wrote", {ws.Relative(out)}}, {"spec", detect::ColourSpecToJson(spec)}});
       }},
      {{"POST", "/api/colour/detect",
        "{video, frames: [N], colour: FILE_OR_PRESET | range, camera?}: ball candidates"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const json body = Body(r);
         const fs::path video = ws.Resolve(Get<std::string>(body, "video"));
         detect::ColourSpec spec;
         if (body.contains("range")) {
           spec = SpecWithBallRange(RangeFromJson(body["range"]));
         } else {
           const std::string c = GetOr<std::string>(body, "colour", "orange");
           bool preset = false;
           for (const auto& n : detect::ColourPresetNames()) preset = preset || n == c;
           spec = preset ? detect::PresetColourSpec(c)
                         : detect::ReadColourSpec(ws.Resolve(c).string());
         }
         std::optional<camera::Camera> cam;
         if (body.contains("camera")) {
           cam = camera::ReadCameraYaml(ws.Resolve(Get<std::string>(body, "camera")).string());
         }
         std::vector<int> frames = GetOr<std::vector<int>>(body, "frames", {0});
         if (frames.empty() || frames.size() > 50) {
           throw HttpError(400, "'frames' must list 1 to 50 frame numbers");
         }
         detect::BallDetector detector(detect::BallDetectorOptions{}, spec, cam ? &*cam : nullptr,
                                       nullptr);
         json out = json::array();
         for (int f : frames) {
           if (f < 0) throw HttpError(400, "frame numbers must be >= 0");
           const cv::Mat bgr = detect::ReadVideoFrame(video.string(), f);
           json cands = json::array();
           for (const auto& c : detector.Detect(bgr)) {
             cands.push_back({{"u", Round(c.centre_px.x(), 1e-3)},
                              {"v", Round(c.centre_px.y(), 1e-3)},
                              {"radius_px", Round(c.radius_px, 1e-3)},
                              {"score", Round(c.score)},
                              {"accepted", c.accepted},
                              {"reason", c.reason}});
           }
           out.push_back({{"frame", f}, {"candidates", cands}});
         }
         return Json({{"frames", out}});
       }},
  };
}

// Endpoints of ball and player tracks, player statistics, zones.
// The player tracks and zones a statistics request names ({tracks[, zones]}), into `o`.
std::vector<track::TrackRow> ReadStatsInput(const Workspace& ws, const json& body,
                                            stats::StatsOptions& o) {
  const fs::path tracks = ws.Resolve(Get<std::string>(body, "tracks"));
  auto rows = track::ReadTracksCsv(tracks.string());
  const track::Roster roster = track::RosterForTracks(tracks.string());
  o.team_of = roster.team_of;
  o.name_of = roster.name_of;
  o.write_video = false;
  if (body.contains("zones") && !body["zones"].is_null()) {
    o.zones = stats::ReadZones(ws.Resolve(Get<std::string>(body, "zones")).string());
  }
  return rows;
}

// Whether `name` is a file a players export writes (the stats report's, zone_alerts.csv, the
// page's images): the files an earlier export left, which a replacing one removes.
bool IsExportFile(const std::string& name) {
  static const std::regex kExport(
      "(players|distances|speed_profiles|zone_alerts)\\.csv|stats\\.json|index\\.html|"
      "radar\\.(png|mp4|avi)|heatmap_[A-Za-z0-9_]+\\.png|page_[A-Za-z0-9_-]+\\.png");
  return std::regex_match(name, kExport);
}

// The files written in `made` (a new folder) moved into `out`, replacing files of their names
// (a link is replaced, never written through); with `replace`, an earlier export's other files
// in `out` go first. A file of the user's, or one this export read, is never removed.
json MoveExportInto(const Workspace& ws, const fs::path& made, const fs::path& out, bool replace,
                    const std::vector<fs::path>& inputs) {
  const auto read_here = [&](const fs::path& p) {
    return std::any_of(inputs.begin(), inputs.end(), [&](const fs::path& input) {
      return util::SameFile(p.string(), input.string());
    });
  };
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(made)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    const fs::path target = out / name;
    if (read_here(target)) {
      throw HttpError(
          409, "'" + ws.Relative(target) + "' is read by this export: choose another folder");
    }
    if (fs::is_directory(fs::symlink_status(target))) {
      throw HttpError(409, "'" + ws.Relative(target) + "' is a folder; not replaced");
    }
  }
  fs::create_directory(out);
  if (replace) {
    std::vector<fs::path> earlier;
    for (const auto& e : fs::directory_iterator(out)) {
      if (!e.is_directory() && !read_here(e.path()) && IsExportFile(e.path().filename().string())) {
        earlier.push_back(e.path());
      }
    }
    for (const fs::path& p : earlier) fs::remove(p);
  }
  json wrote = json::array();
  for (const std::string& name : names) {
    fs::rename(made / name, out / name);
    wrote.push_back(ws.Relative(out / name));
  }
  return wrote;
}

// POST /api/players/export. Everything is checked before anything is written; the files are
// written into a new folder beside OUT and then moved into it. An OUT that is not empty is
// refused (409) unless the request says replace: then an earlier export's files there are
// replaced (those of players that are gone removed too) and any other file is kept.
ApiResponse ExportPlayers(const Workspace& ws, EventHub* events, const ApiRequest& r) {
  const json body = Body(r);
  const fs::path out = ResolveOutputFolder(ws, Get<std::string>(body, "out"));
  std::error_code ec;
  const bool replace = GetOr<bool>(body, "replace", false);
  if (fs::is_directory(out, ec) && !fs::is_empty(out, ec) && !replace) {
    throw HttpError(409, "folder '" + ws.Relative(out) +
                             "' is not empty: choose another folder, or replace the export "
                             "there (replace: true; other files are kept)");
  }
  const field::FieldModel field = LoadFieldIn(ws, GetOr<std::string>(body, "field", "robocup-msl"));
  std::vector<std::pair<std::string, cv::Mat>> images;
  const json sent = GetOr<json>(body, "images", json::object());
  if (!sent.is_object() || sent.size() > 8) {
    throw HttpError(400, "'images' must be an object of at most 8 {name: PNG base64}");
  }
  static const std::regex kName("[A-Za-z0-9_-]{1,40}");
  for (const auto& [name, data] : sent.items()) {
    if (!std::regex_match(name, kName)) {
      throw HttpError(400, "image name '" + name + "' is not 1-40 letters, digits, _ or -");
    }
    if (!data.is_string()) throw HttpError(400, "image '" + name + "' is not a string");
    images.emplace_back("page_" + name + ".png",
                        DecodePngImage(data.get<std::string>(), "image '" + name + "'"));
  }
  stats::StatsOptions o;
  const auto rows = ReadStatsInput(ws, body, o);
  const stats::StatsResult res = stats::ComputeStats(rows, o);

  const fs::path tmp = NewFolderBeside(out, "export");
  FV_REQUIRE(!tmp.empty(), "cannot create a folder beside '{}'", ws.Relative(out));
  json wrote = json::array();
  stats::ReportFiles files;
  try {
    files = stats::WriteStatsReport(res, field, o, tmp.string());
    util::CsvWriter alerts((tmp / "zone_alerts.csv").string(), {"zone", "id", "enter_s", "exit_s"},
                           3);
    for (const auto& e : res.events) {
      alerts << e.zone << e.id << e.enter_s << e.exit_s;
      alerts.EndRow();
    }
    alerts.Close();
    for (const auto& [name, image] : images) {
      const std::string png = EncodePng(image);
      std::ofstream f(tmp / name, std::ios::binary);
      f.write(png.data(), static_cast<std::streamsize>(png.size()));
      FV_REQUIRE(f.good(), "cannot write '{}'", name);
    }
    std::vector<fs::path> inputs = {ws.Resolve(Get<std::string>(body, "tracks"))};
    if (body.contains("zones") && !body["zones"].is_null()) {
      inputs.push_back(ws.Resolve(Get<std::string>(body, "zones")));
    }
    wrote = MoveExportInto(ws, tmp, out, replace, inputs);
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
  fs::remove_all(tmp, ec);
  Saved(events, ws, out, "players export");
  return Json({{"wrote", wrote}, {"notes", files.notes}, {"summary", OneLine(res.Summary())}});
}

std::vector<Route> TrackRoutes() {
  return {
      {{"GET", "/api/ball", "?path=BALL.csv: the ball track (time, position, cameras, error)"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const recon::BallTrackFile track =
             recon::ReadBallTrack(ws.Resolve(Param(r, "path")).string());
         json samples = json::array();
         for (const auto& s : track.samples) {
           samples.push_back({s.frame, s.time_s, Round(s.ball_in_world.x()),
                              Round(s.ball_in_world.y()), Round(s.ball_in_world.z()), s.n_cams,
                              Round(s.err_px)});
         }
         return Json({{"columns", {"frame", "time_s", "x_m", "y_m", "z_m", "n_cams", "err_px"}},
                      {"samples", samples},
                      {"skipped", track.skipped.size()}});
       }},
      {{"GET", "/api/tracks",
        "?path=TRACKS.csv: player tracks (frame, id, box, x_m, y_m, time_s, team from its roster "
        "TRACKS.csv.teams.csv or its own team column)"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const fs::path path = ws.Resolve(Param(r, "path"));
         const util::CsvTable t = util::CsvTable::Read(path.string());
         t.Require({"frame", "id", "bb_left", "bb_top", "bb_width", "bb_height"});
         const track::Roster roster = track::RosterForTracks(path.string());
         json rows = json::array();
         auto num = [&](size_t i, const char* col) -> json {
           if (!t.Has(col) || t.Get(i, col).empty()) return nullptr;
           return t.GetDouble(i, col);
         };
         for (size_t i = 0; i < t.rows(); ++i) {
           const auto team = roster.team_of.find(static_cast<int>(t.GetInt(i, "id")));
           rows.push_back({t.GetInt(i, "frame"), t.GetInt(i, "id"), num(i, "bb_left"),
                           num(i, "bb_top"), num(i, "bb_width"), num(i, "bb_height"), num(i, "x_m"),
                           num(i, "y_m"), num(i, "time_s"),
                           team == roster.team_of.end() ? json(nullptr) : json(team->second)});
         }
         return Json({{"columns",
                       {"frame", "id", "bb_left", "bb_top", "bb_width", "bb_height", "x_m", "y_m",
                        "time_s", "team"}},
                      {"rows", rows}});
       }},
      {{"POST", "/api/players/stats",
        "{tracks[, zones]}: per player distance, top speed (1-s mean), sprints, zone time and the "
        "zone alerts (who entered which zone, when), as `stats` computes them"},
       [](const Workspace& ws, EventHub*, JobRunner*, LiveFeed*, const ApiRequest& r) {
         const json body = Body(r);
         stats::StatsOptions o;
         const auto rows = ReadStatsInput(ws, body, o);
         const stats::StatsResult res = stats::ComputeStats(rows, o);
         json players = json::array();
         for (const auto& p : res.players) {
           json profile = json::array();
           for (const auto& [t, v] : p.speed_profile) {
             profile.push_back({Round(t, 1e-3), Round(v, 1e-3)});
           }
           players.push_back({{"id", p.id},
                              {"team", p.team},
                              {"samples", p.samples},
                              {"first_s", Round(p.first_s, 1e-3)},
                              {"last_s", Round(p.last_s, 1e-3)},
                              {"distance_m", Round(p.distance_m, 1e-3)},
                              {"top_speed_mps", Round(p.top_speed_mps, 1e-3)},
                              {"mean_speed_mps", Round(p.mean_speed_mps, 1e-3)},
                              {"sprints", p.sprints},
                              {"zone_time_s", p.zone_time_s},
                              {"speed_profile", profile}});
         }
         json events = json::array();
         for (const auto& e : res.events) {
           events.push_back({{"zone", e.zone},
                             {"id", e.id},
                             {"enter_s", Round(e.enter_s, 1e-3)},
                             {"exit_s", Round(e.exit_s, 1e-3)}});
         }
         return Json({{"players", players},
                      {"events", events},
                      {"duration_s", Round(res.duration_s, 1e-3)},
                      {"fps", Round(res.fps, 1e-3)},
                      {"summary", OneLine(res.Summary())}});
       }},
      {{"POST", "/api/players/export",
        "{tracks[, zones, field, images: {name: PNG base64}], out: FOLDER[, replace]}: the "
        "Players page's "
        "export: `stats` report (players.csv, speed_profiles.csv, distances.csv, heat maps with "
        "scales, radar.png, stats.json, index.html), zone_alerts.csv, the page's images as "
        "page_NAME.png"},
       [](const Workspace& ws, EventHub* events, JobRunner*, LiveFeed*, const ApiRequest& r) {
         return ExportPlayers(ws, events, r);
       }},
      {{"GET", "/api/zones", "?path=zones.json: named polygons on the field (stats --zones)"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         json zones = json::array();
         for (const auto& z : stats::ReadZones(ws.Resolve(Param(r, "path")).string())) {
           json polygon = json::array();
           for (const auto& p : z.polygon_m) polygon.push_back({p.x(), p.y()});
           zones.push_back({{"name", z.name}, {"polygon", polygon}});
         }
         return Json(zones);
       }},
      {{"POST", "/api/zones/save", "{zones: [{name, polygon: [[x, y], ...]}], out}: zones file"},
       [](const Workspace& ws, EventHub* events, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const json body = Body(r);
         const json zones = Get<json>(body, "zones");
         if (!zones.is_array()) throw HttpError(400, "'zones' must be an array");
         const fs::path out = SaveTarget(ws, body, "out", {".json"});
         SaveZones(zones, out);
         Saved(events, ws, out, "zones");
         return Json({{"wrote", {ws.Relative(out)}}, {"zones", zones.size()}});
       }},
  };
}

// Endpoints of jobs and JSON files.
std::vector<Route> JobRoutes() {
  return {
      {{"GET", "/api/jobs", "the jobs, newest first (state, progress line, output)"},
       [](const Workspace&, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest&) {
         if (!jobs) throw HttpError(404, "this server runs no jobs");
         return Json(jobs->List());
       }},
      {{"POST", "/api/jobs",
        "{command: ball|trajectory|players|stats|plan|detect|synth, args: [...], replace: false}: "
        "start a job (an existing output is refused unless replace)"},
       [](const Workspace&, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         if (!jobs) throw HttpError(404, "this server runs no jobs");
         const json body = Body(r);
         const int id = jobs->Start(Get<std::string>(body, "command"),
                                    GetOr<std::vector<std::string>>(body, "args", {}),
                                    GetOr<bool>(body, "replace", false));
         return Json(jobs->Get(id));
       }},
      {{"POST", "/api/jobs/cancel", "{id}: end a running job"},
       [](const Workspace&, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         if (!jobs) throw HttpError(404, "this server runs no jobs");
         const int id = Get<int>(Body(r), "id");
         const bool cancelled = jobs->Cancel(id);
         return Json({{"id", id}, {"cancelled", cancelled}});
       }},
      {{"GET", "/api/json", "?path=F.json: a JSON file of the folder (FLIGHTS.json, ...)"},
       [](const Workspace& ws, EventHub*, JobRunner* jobs, LiveFeed*, const ApiRequest& r) {
         const fs::path p = ws.Resolve(Param(r, "path"));
         std::ifstream in(p, std::ios::binary);
         if (!in) throw HttpError(404, "cannot read '" + Param(r, "path") + "'");
         std::stringstream text;
         text << in.rdbuf();
         if (util::JsonNestingDepth(text.view()) > util::kMaxJsonDepth) {
           throw HttpError(422, fmt::format("'{}' nests arrays or objects deeper than {} levels",
                                            Param(r, "path"), util::kMaxJsonDepth));
         }
         try {
           return Json(json::parse(text.view()));
         } catch (const json::parse_error&) {
           throw HttpError(422, "'" + Param(r, "path") + "' is not valid JSON");
         }
       }},
  };
}

const std::vector<Route>& Routes() {
  static const std::vector<Route> kRoutes = [] {
    std::vector<Route> all;
    for (auto group : {FolderRoutes, CalibrationRoutes, IntrinsicsAndLiveRoutes, ColourRoutes,
                       TrackRoutes, JobRoutes}) {
      for (Route& r : group()) all.push_back(std::move(r));
    }
    return all;
  }();
  return kRoutes;
}

}  // namespace

StudioApi::StudioApi(const Workspace& workspace, EventHub* events, JobRunner* jobs, LiveFeed* live)
    : workspace_(workspace), events_(events), jobs_(jobs), live_(live) {}

const std::vector<Endpoint>& StudioApi::Endpoints() {
  static const std::vector<Endpoint> kEndpoints = [] {
    std::vector<Endpoint> e;
    for (const auto& r : Routes()) e.push_back(r.endpoint);
    e.push_back(
        {"GET", "/api/events", "Server-Sent Events: saved files, job progress, live positions"});
    return e;
  }();
  return kEndpoints;
}

ApiResponse StudioApi::Handle(const ApiRequest& request) const {
  bool path_known = false;
  for (const auto& route : Routes()) {
    if (route.endpoint.path != request.path) continue;
    path_known = true;
    if (route.endpoint.method != request.method) continue;
    try {
      return route.handler(workspace_, events_, jobs_, live_, request);
    } catch (const HttpError& e) {
      return ErrorResponse(e.status(), e.what());
    } catch (const fv::Error& e) {
      // Library errors name the input (bad file content, too few points, ...).
      return ErrorResponse(422, e.what());
    } catch (const json::exception& e) {
      return ErrorResponse(400, std::string("bad request: ") + e.what());
    } catch (const cv::Exception& e) {
      return ErrorResponse(422, std::string("OpenCV: ") + e.err);
    } catch (const std::exception& e) {
      return ErrorResponse(500, std::string("internal error: ") + e.what());
    }
  }
  if (path_known) return ErrorResponse(405, request.method + " is not allowed on " + request.path);
  return ErrorResponse(404, "unknown endpoint " + request.path);
}

}  // namespace fv::web
