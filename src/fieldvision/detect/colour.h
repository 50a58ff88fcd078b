// Colour classes for the ball path (RoboCup-style colour segmentation): each class is a union of
// boxes in HSV (hue in degrees, wrapping when min > max) or YUV (OpenCV's BT.601 8-bit
// conversion), compiled into a lookup table that maps a packed BGR value to a bit set of
// classes: the exact 2^24-entry table (16 MiB) or a quantised one (2^(3b) entries for b bits per
// channel, each cell takes the class of its centre). Presets (orange, yellow, white, pink, ...)
// and JSON colour files (what `color learn` writes and `--color` reads). Written by hand because
// this table is the product's fast path; OpenCV's cvtColor does the colour conversions once.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "fieldvision/util/huge_buffer.h"

namespace fv::detect {

enum class ColourSpace { kHsv, kYuv };

// One box. HSV: min/max = (hue degrees 0..360, saturation 0..255, value 0..255); a hue range
// with min > max wraps through 0 (reds). YUV: (Y, U, V) 0..255 as cv::COLOR_BGR2YUV.
struct ColourRange {
  ColourSpace space = ColourSpace::kHsv;
  std::array<double, 3> min = {0, 0, 0};
  std::array<double, 3> max = {360, 255, 255};
};

struct ColourClass {
  std::string name;
  std::vector<ColourRange> ranges;  // a pixel belongs to the class if it is in any range
};

// At most 8 classes (one bit each in the table); `ball_class` names the ball's.
struct ColourSpec {
  std::vector<ColourClass> classes;
  std::string ball_class = "ball";
  // Throws fv::Error naming `context` and the bad class or range.
  void Check(const std::string& context = "colour spec") const;
  // Index of a class; -1 if absent.
  int Find(const std::string& name) const;
};

// Names of the presets: orange, yellow, white, pink, red, blue, green, black.
std::vector<std::string> ColourPresetNames();
// One preset class (named after the preset); throws listing the names when unknown.
ColourClass ColourPreset(const std::string& name);
// A spec whose ball class is the preset `ball_preset`, plus "field" (green) and "line" (white).
ColourSpec PresetColourSpec(const std::string& ball_preset = "orange");

// The ball class widened for the shaded, pale and blurred parts of a ball that touch its core
// colour (region growing with hysteresis, as Canny's two thresholds): HSV hue +-hue_deg,
// saturation and value minima times `factor`; YUV chroma +-2 * hue_deg, Y minimum times
// `factor`. The result has the one class `ball_class`.
ColourSpec WidenedBallSpec(const ColourSpec& spec, double hue_deg = 10.0, double factor = 0.6);
// `spec` with that widened class added under the name WidenedBallClass(spec), so that one table
// holds both (one lookup, one table to build, cache and keep in memory); `spec` unchanged when it
// has no room (8 classes) or already has a class of that name.
ColourSpec WithWidenedBall(const ColourSpec& spec, double hue_deg = 10.0, double factor = 0.6);
std::string WidenedBallClass(const ColourSpec& spec);

nlohmann::json ColourSpecToJson(const ColourSpec& spec);
// Throws fv::Error naming `context` and the bad key.
ColourSpec ColourSpecFromJson(const nlohmann::json& j, const std::string& context);
// Reads a colour file; an absent, empty or invalid file throws fv::Error naming it.
ColourSpec ReadColourSpec(const std::string& path);
void WriteColourSpec(const ColourSpec& spec, const std::string& path);
// `--color SPEC`: a preset name (PresetColourSpec) or the path of a colour file.
ColourSpec LoadColourSpec(const std::string& preset_or_path);

// HSV (degrees, 0..255, 0..255) and YUV of one BGR pixel, as the table sees them.
std::array<double, 3> BgrToHsv(uint8_t b, uint8_t g, uint8_t r);
std::array<double, 3> BgrToYuv(uint8_t b, uint8_t g, uint8_t r);
bool RangeContains(const ColourRange& range, const std::array<double, 3>& hsv,
                   const std::array<double, 3>& yuv);
// The class bits the spec's ranges give one colour, computed directly (what a table holds).
uint8_t ClassifyBySpec(const ColourSpec& spec, uint8_t b, uint8_t g, uint8_t r);

// The compiled lookup table. bits_per_channel 8: exact 2^24 table; 5..7: quantised.
class ColourTable {
 public:
  explicit ColourTable(const ColourSpec& spec, int bits_per_channel = 8);
  // Shared, cached tables: detectors built for several cameras with one spec share one table,
  // loaded from the disk cache (colour_cache.h) when it holds one, else built and stored there.
  static std::shared_ptr<const ColourTable> Shared(const ColourSpec& spec,
                                                   int bits_per_channel = 8);
  // Whether `samples` pseudo-random colours (the same each call) classify as the spec's ranges
  // say, colour by colour (BgrToHsv, BgrToYuv, RangeContains).
  bool AgreesWithSpec(int samples) const;

  const ColourSpec& spec() const { return spec_; }
  int bits_per_channel() const { return bits_; }
  // Bit of a class (1 << index); throws naming the class when absent.
  uint8_t ClassBit(const std::string& name) const;
  // The same, 0 when the spec has no such class (a preset without "field" or "line").
  uint8_t ClassBitOrZero(const std::string& name) const;
  uint8_t BallBit() const { return ClassBit(spec_.ball_class); }

  // Table index of a packed BGR value (b | g << 8 | r << 16).
  uint32_t Index(uint32_t packed_bgr) const {
    if (bits_ == 8) return packed_bgr;
    const uint32_t s = 8 - bits_, m = (1u << bits_) - 1;
    return ((packed_bgr >> s) & m) | (((packed_bgr >> (8 + s)) & m) << bits_) |
           (((packed_bgr >> (16 + s)) & m) << (2 * bits_));
  }
  uint8_t Classify(uint8_t b, uint8_t g, uint8_t r) const {
    return table_[Index(uint32_t(b) | uint32_t(g) << 8 | uint32_t(r) << 16)];
  }
  const uint8_t* data() const { return table_.data(); }
  // Class bits of n pixels of a BGR row, `step` pixels apart from `bgr` on, into `cls` (kStep >
  // 0: the step known at compile time, for the scans' inner loops). With the exact table a
  // pixel's packed value is one 4-byte load (little-endian, the byte after it masked off), but the
  // last pixel's, whose next byte may lie past the row; eight pixels an iteration (a third of the
  // loop's instructions are its own otherwise).
  template <int kStep = 0>
  void ClassifyRow(const uint8_t* bgr, int n, int step, uint8_t* cls) const {
    const ptrdiff_t stride = 3 * static_cast<ptrdiff_t>(kStep > 0 ? kStep : step);
    const uint8_t* lut = table_.data();
    if (bits_ == 8 && std::endian::native == std::endian::little && n > 1) {
      const auto one = [&](int k) {
        uint32_t v;
        std::memcpy(&v, bgr + k * stride, sizeof(v));
        cls[k] = lut[v & 0xFFFFFFu];
      };
      int i = 0;
      for (; i + 8 < n; i += 8, bgr += 8 * stride, cls += 8) {
        one(0), one(1), one(2), one(3), one(4), one(5), one(6), one(7);
      }
      for (; i + 1 < n; ++i, bgr += stride, ++cls) one(0);
      cls[0] = Classify(bgr[0], bgr[1], bgr[2]);
      return;
    }
    for (int i = 0; i < n; ++i, bgr += stride) {
      cls[i] = lut[Index(uint32_t(bgr[0]) | uint32_t(bgr[1]) << 8 | uint32_t(bgr[2]) << 16)];
    }
  }
  // Class bits of every pixel of a BGR image (CV_8U).
  cv::Mat ClassifyImage(const cv::Mat& bgr) const;

 private:
  // Entries of a table of this many bits per channel; throws fv::Error outside 4..8.
  static size_t Entries(int bits_per_channel);
  ColourTable(const ColourSpec& spec, int bits_per_channel, util::HugeBuffer table);
  ColourSpec spec_;
  int bits_;
  util::HugeBuffer table_;  // on huge pages: 16 MB read at random, one read a pixel
};

}  // namespace fv::detect
