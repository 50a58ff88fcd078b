#include "fieldvision/detect/colour.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include <opencv2/core/version.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/colour_cache.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/output_path.h"

namespace fv::detect {
namespace {

using nlohmann::json;

ColourRange Hsv(double h0, double s0, double v0, double h1, double s1, double v1) {
  return {ColourSpace::kHsv, {h0, s0, v0}, {h1, s1, v1}};
}

const std::map<std::string, std::vector<ColourRange>>& Presets() {
  // Hue in degrees. Orange covers Lambert-shaded balls (dark side down to V 45) but not skin
  // (low saturation) or red shirts (hue < 6). Yellow adds, for bright light, a paler box (a
  // yellow ball overexposed or in white light turns cream) and reaches hue 78: a far ball's few
  // pixels mix with the green carpet (JPEG halves the chroma resolution) and turn yellow-green.
  // Measured on the MSL photos in shared/data/robocup-ball-photos (share of ball pixels against
  // background pixels, per box: hue 68 -> 78 puts 98 instead of 87 of 117 balls at least 20 %
  // in the class, the background share 0.27 -> 0.30 %).
  static const std::map<std::string, std::vector<ColourRange>> kPresets = {
      {"orange", {Hsv(6, 170, 45, 38, 255, 255)}},
      {"yellow", {Hsv(40, 100, 80, 78, 255, 255), Hsv(30, 48, 176, 62, 255, 255)}},
      {"white", {Hsv(0, 0, 170, 360, 45, 255)}},
      {"pink", {Hsv(295, 60, 120, 345, 255, 255)}},
      {"red", {Hsv(345, 120, 60, 6, 255, 255)}},
      {"blue", {Hsv(190, 100, 50, 250, 255, 255)}},
      {"green", {Hsv(70, 50, 30, 170, 255, 255)}},
      {"black", {Hsv(0, 0, 0, 360, 255, 45)}},
  };
  return kPresets;
}

const char* SpaceName(ColourSpace s) { return s == ColourSpace::kHsv ? "hsv" : "yuv"; }

// Per channel, which 8-bit values of the converted image are inside the range.
struct CompiledRange {
  ColourSpace space;
  std::array<std::array<uint8_t, 256>, 3> in;
};

CompiledRange Compile(const ColourRange& r) {
  CompiledRange c{r.space, {}};
  for (int ch = 0; ch < 3; ++ch) {
    for (int v = 0; v < 256; ++v) {
      bool inside;
      if (r.space == ColourSpace::kHsv && ch == 0) {
        const double deg = v * 360.0 / 256.0;
        inside = r.min[0] <= r.max[0] ? (deg >= r.min[0] && deg <= r.max[0])
                                      : (deg >= r.min[0] || deg <= r.max[0]);
      } else {
        inside = v >= r.min[ch] && v <= r.max[ch];
      }
      c.in[ch][v] = inside ? 1 : 0;
    }
  }
  return c;
}

std::array<double, 3> Array3(const json& j, const std::string& where) {
  FV_REQUIRE(j.is_array() && j.size() == 3, "{} must be an array of 3 numbers", where);
  std::array<double, 3> a;
  for (int i = 0; i < 3; ++i) {
    FV_REQUIRE(j[i].is_number(), "{}[{}] is not a number", where, i);
    a[i] = j[i].get<double>();
  }
  return a;
}

}  // namespace

void ColourSpec::Check(const std::string& context) const {
  FV_REQUIRE(!classes.empty(), "{}: no colour classes", context);
  FV_REQUIRE(classes.size() <= 8, "{}: {} classes; at most 8 fit the table", context,
             classes.size());
  std::set<std::string> names;
  for (size_t i = 0; i < classes.size(); ++i) {
    const ColourClass& c = classes[i];
    FV_REQUIRE(!c.name.empty(), "{}: classes[{}] has no name", context, i);
    FV_REQUIRE(names.insert(c.name).second, "{}: class '{}' appears twice", context, c.name);
    FV_REQUIRE(!c.ranges.empty(), "{}: class '{}' has no ranges", context, c.name);
    for (size_t k = 0; k < c.ranges.size(); ++k) {
      const ColourRange& r = c.ranges[k];
      for (int ch = 0; ch < 3; ++ch) {
        FV_REQUIRE(std::isfinite(r.min[ch]) && std::isfinite(r.max[ch]),
                   "{}: class '{}' ranges[{}] has a non-finite bound", context, c.name, k);
        const double hi = (r.space == ColourSpace::kHsv && ch == 0) ? 360.0 : 255.0;
        FV_REQUIRE(r.min[ch] >= 0 && r.max[ch] <= hi && r.max[ch] >= 0 && r.min[ch] <= hi,
                   "{}: class '{}' ranges[{}] channel {} outside 0..{}", context, c.name, k, ch,
                   hi);
        if (!(r.space == ColourSpace::kHsv && ch == 0)) {
          FV_REQUIRE(r.min[ch] <= r.max[ch], "{}: class '{}' ranges[{}] channel {} has min > max",
                     context, c.name, k, ch);
        }
      }
    }
  }
  FV_REQUIRE(Find(ball_class) >= 0, "{}: ball_class '{}' is not one of the classes", context,
             ball_class);
}

int ColourSpec::Find(const std::string& name) const {
  for (size_t i = 0; i < classes.size(); ++i) {
    if (classes[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<std::string> ColourPresetNames() {
  return {"orange", "yellow", "white", "pink", "red", "blue", "green", "black"};
}

ColourClass ColourPreset(const std::string& name) {
  const auto it = Presets().find(name);
  if (it == Presets().end()) {
    std::string names;
    for (const auto& n : ColourPresetNames()) names += (names.empty() ? "" : ", ") + n;
    Throw("unknown colour preset '{}' (presets: {})", name, names);
  }
  return {name, it->second};
}

ColourSpec PresetColourSpec(const std::string& ball_preset) {
  ColourSpec spec;
  ColourClass ball = ColourPreset(ball_preset);
  ball.name = "ball";
  spec.classes.push_back(ball);
  if (ball_preset != "green") spec.classes.push_back({"field", ColourPreset("green").ranges});
  if (ball_preset != "white") spec.classes.push_back({"line", ColourPreset("white").ranges});
  spec.ball_class = "ball";
  return spec;
}

ColourSpec WidenedBallSpec(const ColourSpec& spec, double hue_deg, double factor) {
  spec.Check("colour spec");
  ColourClass wide = spec.classes[spec.Find(spec.ball_class)];
  for (ColourRange& r : wide.ranges) {
    if (r.space == ColourSpace::kHsv) {
      const bool full = r.min[0] == 0 && r.max[0] == 360;
      if (!full) {
        r.min[0] = std::fmod(r.min[0] - hue_deg + 360.0, 360.0);
        r.max[0] = std::fmod(r.max[0] + hue_deg, 360.0);
      }
      r.min[1] *= factor;
      r.min[2] *= factor;
    } else {
      r.min[0] *= factor;
      for (int ch = 1; ch < 3; ++ch) {
        r.min[ch] = std::max(0.0, r.min[ch] - 2 * hue_deg);
        r.max[ch] = std::min(255.0, r.max[ch] + 2 * hue_deg);
      }
    }
  }
  ColourSpec out;
  out.classes = {wide};
  out.ball_class = wide.name;
  return out;
}

std::string WidenedBallClass(const ColourSpec& spec) { return spec.ball_class + " (widened)"; }

ColourSpec WithWidenedBall(const ColourSpec& spec, double hue_deg, double factor) {
  ColourClass wide = WidenedBallSpec(spec, hue_deg, factor).classes[0];
  wide.name = WidenedBallClass(spec);
  if (spec.classes.size() >= 8 || spec.Find(wide.name) >= 0) return spec;
  ColourSpec out = spec;
  out.classes.push_back(std::move(wide));
  return out;
}

json ColourSpecToJson(const ColourSpec& spec) {
  json classes = json::array();
  for (const auto& c : spec.classes) {
    json ranges = json::array();
    for (const auto& r : c.ranges) {
      ranges.push_back({{"space", SpaceName(r.space)}, {"min", r.min}, {"max", r.max}});
    }
    classes.push_back({{"name", c.name}, {"ranges", ranges}});
  }
  return {{"format", "fieldvision colour classes"},
          {"note",
           "hsv: hue degrees 0..360 (min > max wraps through 0), saturation and value 0..255; "
           "yuv: OpenCV BT.601 8-bit"},
          {"ball_class", spec.ball_class},
          {"classes", classes}};
}

ColourSpec ColourSpecFromJson(const json& j, const std::string& context) {
  FV_REQUIRE(j.is_object(), "{}: expected a JSON object with 'classes'", context);
  FV_REQUIRE(j.contains("classes") && j["classes"].is_array(), "{}: missing array 'classes'",
             context);
  ColourSpec spec;
  for (size_t i = 0; i < j["classes"].size(); ++i) {
    const json& jc = j["classes"][i];
    const std::string where = fmt::format("{}: classes[{}]", context, i);
    FV_REQUIRE(jc.is_object() && jc.contains("name") && jc["name"].is_string(),
               "{} needs a string 'name'", where);
    ColourClass c;
    c.name = jc["name"].get<std::string>();
    FV_REQUIRE(jc.contains("ranges") && jc["ranges"].is_array(), "{} needs an array 'ranges'",
               where);
    for (size_t k = 0; k < jc["ranges"].size(); ++k) {
      const json& jr = jc["ranges"][k];
      const std::string rwhere = fmt::format("{}.ranges[{}]", where, k);
      FV_REQUIRE(jr.is_object(), "{} is not an object", rwhere);
      ColourRange r;
      const std::string space = jr.value("space", std::string("hsv"));
      FV_REQUIRE(space == "hsv" || space == "yuv", "{}.space '{}' is not hsv or yuv", rwhere,
                 space);
      r.space = space == "hsv" ? ColourSpace::kHsv : ColourSpace::kYuv;
      FV_REQUIRE(jr.contains("min") && jr.contains("max"), "{} needs 'min' and 'max'", rwhere);
      r.min = Array3(jr["min"], rwhere + ".min");
      r.max = Array3(jr["max"], rwhere + ".max");
      c.ranges.push_back(r);
    }
    spec.classes.push_back(c);
  }
  if (j.contains("ball_class")) {
    FV_REQUIRE(j["ball_class"].is_string(), "{}: 'ball_class' is not a string", context);
    spec.ball_class = j["ball_class"].get<std::string>();
  } else if (!spec.classes.empty()) {
    spec.ball_class = spec.classes.front().name;
  }
  spec.Check(context);
  return spec;
}

ColourSpec ReadColourSpec(const std::string& path) {
  return ColourSpecFromJson(util::ReadJsonFile(path, "colour"),
                            fmt::format("colour file '{}'", path));
}

void WriteColourSpec(const ColourSpec& spec, const std::string& path) {
  spec.Check("colour spec to write");
  util::WriteTextFile(path, ColourSpecToJson(spec).dump(2) + "\n", "colour file");
}

ColourSpec LoadColourSpec(const std::string& preset_or_path) {
  FV_REQUIRE(!preset_or_path.empty(), "--color is empty: give a preset name or a colour file");
  std::error_code ec;
  if (Presets().count(preset_or_path) && !std::filesystem::exists(preset_or_path, ec)) {
    return PresetColourSpec(preset_or_path);
  }
  if (!std::filesystem::exists(preset_or_path, ec)) {
    std::string names;
    for (const auto& n : ColourPresetNames()) names += (names.empty() ? "" : ", ") + n;
    Throw("colour '{}' is neither a preset ({}) nor an existing colour file", preset_or_path,
          names);
  }
  return ReadColourSpec(preset_or_path);
}

std::array<double, 3> BgrToHsv(uint8_t b, uint8_t g, uint8_t r) {
  cv::Mat px(1, 1, CV_8UC3, cv::Scalar(b, g, r)), hsv;
  cv::cvtColor(px, hsv, cv::COLOR_BGR2HSV_FULL);
  const cv::Vec3b v = hsv.at<cv::Vec3b>(0, 0);
  return {v[0] * 360.0 / 256.0, double(v[1]), double(v[2])};
}

std::array<double, 3> BgrToYuv(uint8_t b, uint8_t g, uint8_t r) {
  cv::Mat px(1, 1, CV_8UC3, cv::Scalar(b, g, r)), yuv;
  cv::cvtColor(px, yuv, cv::COLOR_BGR2YUV);
  const cv::Vec3b v = yuv.at<cv::Vec3b>(0, 0);
  return {double(v[0]), double(v[1]), double(v[2])};
}

bool RangeContains(const ColourRange& range, const std::array<double, 3>& hsv,
                   const std::array<double, 3>& yuv) {
  const auto& p = range.space == ColourSpace::kHsv ? hsv : yuv;
  for (int ch = 0; ch < 3; ++ch) {
    if (range.space == ColourSpace::kHsv && ch == 0) {
      const bool in = range.min[0] <= range.max[0] ? (p[0] >= range.min[0] && p[0] <= range.max[0])
                                                   : (p[0] >= range.min[0] || p[0] <= range.max[0]);
      if (!in) return false;
    } else if (p[ch] < range.min[ch] || p[ch] > range.max[ch]) {
      return false;
    }
  }
  return true;
}

ColourTable::ColourTable(const ColourSpec& spec, int bits_per_channel)
    : spec_(spec), bits_(bits_per_channel) {
  spec_.Check();
  const size_t entries = Entries(bits_);
  const int n = 1 << bits_;
  const int shift = 8 - bits_;
  const int centre = shift > 0 ? 1 << (shift - 1) : 0;
  table_ = util::HugeBuffer(entries);  // zeroed
  // Compiled ranges per class.
  std::vector<std::pair<uint8_t, CompiledRange>> ranges;
  bool need_hsv = false, need_yuv = false;
  for (size_t k = 0; k < spec_.classes.size(); ++k) {
    for (const auto& r : spec_.classes[k].ranges) {
      ranges.push_back({uint8_t(1u << k), Compile(r)});
      (r.space == ColourSpace::kHsv ? need_hsv : need_yuv) = true;
    }
  }
  // One n x n image (b along columns, g along rows) per red level, converted by OpenCV; the red
  // levels fill disjoint slices of the table, in parallel. OpenCV fills its own conversion tables
  // on a first call without a lock: make that call here, before the threads.
  {
    const cv::Mat pixel(1, 1, CV_8UC3, cv::Scalar::all(0));
    cv::Mat converted;
    if (need_hsv) cv::cvtColor(pixel, converted, cv::COLOR_BGR2HSV_FULL);
    if (need_yuv) cv::cvtColor(pixel, converted, cv::COLOR_BGR2YUV);
  }
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& red_levels) {
    cv::Mat bgr(n, n, CV_8UC3), hsv, yuv;
    for (int ri = red_levels.start; ri < red_levels.end; ++ri) {
      for (int gi = 0; gi < n; ++gi) {
        cv::Vec3b* row = bgr.ptr<cv::Vec3b>(gi);
        for (int bi = 0; bi < n; ++bi) {
          row[bi] = cv::Vec3b(uint8_t((bi << shift) + centre), uint8_t((gi << shift) + centre),
                              uint8_t((ri << shift) + centre));
        }
      }
      if (need_hsv) cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV_FULL);
      if (need_yuv) cv::cvtColor(bgr, yuv, cv::COLOR_BGR2YUV);
      uint8_t* out = table_.data() + size_t(ri) * n * n;
      for (const auto& [bit, cr] : ranges) {
        const cv::Mat& conv = cr.space == ColourSpace::kHsv ? hsv : yuv;
        const uint8_t* p = conv.ptr<uint8_t>(0);  // continuous
        const uint8_t* in0 = cr.in[0].data();
        const uint8_t* in1 = cr.in[1].data();
        const uint8_t* in2 = cr.in[2].data();
        const size_t pixels = static_cast<size_t>(n) * static_cast<size_t>(n);
        for (size_t i = 0; i < pixels; ++i) {
          const uint8_t inside = in0[p[3 * i]] & in1[p[3 * i + 1]] & in2[p[3 * i + 2]];
          out[i] |= uint8_t(bit * inside);
        }
      }
    }
  });
}

uint8_t ClassifyBySpec(const ColourSpec& spec, uint8_t b, uint8_t g, uint8_t r) {
  const auto hsv = BgrToHsv(b, g, r);
  const auto yuv = BgrToYuv(b, g, r);
  uint8_t bits = 0;
  for (size_t k = 0; k < spec.classes.size(); ++k) {
    for (const ColourRange& range : spec.classes[k].ranges) {
      if (RangeContains(range, hsv, yuv)) bits |= uint8_t(1u << k);
    }
  }
  return bits;
}

size_t ColourTable::Entries(int bits_per_channel) {
  FV_REQUIRE(bits_per_channel >= 4 && bits_per_channel <= 8, "lut_bits must be 4..8 (got {})",
             bits_per_channel);
  return size_t(1) << (3 * bits_per_channel);
}

ColourTable::ColourTable(const ColourSpec& spec, int bits_per_channel, util::HugeBuffer table)
    : spec_(spec), bits_(bits_per_channel), table_(std::move(table)) {}

bool ColourTable::AgreesWithSpec(int samples) const {
  const int shift = 8 - bits_;
  const int centre = shift > 0 ? 1 << (shift - 1) : 0;
  uint32_t state = 12345u;
  for (int i = 0; i < samples; ++i) {
    state = state * 1664525u + 1013904223u;  // Numerical Recipes' LCG
    const auto level = [&](int at) {
      return uint8_t((((state >> at) & 0xFFu) >> shift << shift) + centre);
    };
    const uint8_t b = level(0), g = level(8), r = level(16);
    if (Classify(b, g, r) != ClassifyBySpec(spec_, b, g, r)) return false;
  }
  return true;
}

namespace {

// The disk cache's key (colour_cache.h): the table's format, OpenCV's version (its colour
// conversions fill the table) and the spec (as JSON).
std::string DiskKey(const std::string& spec_json, int bits) {
  return fmt::format("colour table 1, {} bits, OpenCV {}\n{}", bits, CV_VERSION, spec_json);
}

}  // namespace

std::shared_ptr<const ColourTable> ColourTable::Shared(const ColourSpec& spec,
                                                       int bits_per_channel) {
  static std::mutex mutex;
  static std::map<std::string, std::weak_ptr<const ColourTable>> cache;
  const std::string spec_json = ColourSpecToJson(spec).dump();
  const std::string key = std::to_string(bits_per_channel) + spec_json;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto existing = cache[key].lock()) return existing;
  // From the disk cache when a table there agrees with the spec on a sample of colours (a table
  // written by other code is rebuilt and written again).
  spec.Check();
  const std::string disk_key = DiskKey(spec_json, bits_per_channel);
  std::shared_ptr<const ColourTable> table;
  const size_t size = Entries(bits_per_channel);
  if (auto stored = LoadCachedTable(disk_key, size)) {
    std::shared_ptr<const ColourTable> loaded(
        new ColourTable(spec, bits_per_channel, std::move(*stored)));
    if (loaded->AgreesWithSpec(4096)) table = std::move(loaded);
  }
  if (!table) {
    table = std::make_shared<const ColourTable>(spec, bits_per_channel);
    StoreCachedTable(disk_key, table->data(), size);
  }
  cache[key] = table;
  return table;
}

uint8_t ColourTable::ClassBit(const std::string& name) const {
  const int i = spec_.Find(name);
  FV_REQUIRE(i >= 0, "colour class '{}' is not in the colour spec", name);
  return uint8_t(1u << i);
}

uint8_t ColourTable::ClassBitOrZero(const std::string& name) const {
  const int i = spec_.Find(name);
  return i >= 0 ? uint8_t(1u << i) : 0;
}

cv::Mat ColourTable::ClassifyImage(const cv::Mat& bgr) const {
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "ClassifyImage: expected a BGR 8-bit image");
  cv::Mat out(bgr.size(), CV_8U);
  for (int y = 0; y < bgr.rows; ++y) {
    const uint8_t* p = bgr.ptr<uint8_t>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < bgr.cols; ++x, p += 3) o[x] = Classify(p[0], p[1], p[2]);
  }
  return out;
}

}  // namespace fv::detect
