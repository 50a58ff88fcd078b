#include "fieldvision/detect/lab.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "fieldvision/util/error.h"

namespace fv::detect {
namespace {

// sRGB 8-bit value -> linear light in [0, 1] (IEC 61966-2-1).
const std::array<double, 256>& LinearTable() {
  static const std::array<double, 256> kTable = [] {
    std::array<double, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[i] = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    }
    return t;
  }();
  return kTable;
}

// The cube root of t in f(t)'s range below, to within 1e-14: a first guess within 4 % from the
// bits divided by three (exponent and mantissa alike), then two of Halley's steps, each cubing the
// relative error. std::cbrt, for any double, was a fifth of the detector's time.
double CubeRoot(double t) {
  uint64_t bits = 0;
  std::memcpy(&bits, &t, sizeof bits);
  bits = bits / 3 + 0x2A9F7893782DA1CEULL;
  double y = 0.0;
  std::memcpy(&y, &bits, sizeof y);
  for (int i = 0; i < 2; ++i) {
    const double y3 = y * y * y;
    y *= (y3 + 2.0 * t) / (2.0 * y3 + t);
  }
  return y;
}

// CIE 1976 f(t): the cube root above (6/29)^3, its tangent line below.
double LabF(double t) { return t > 0.008856 ? CubeRoot(t) : 7.787 * t + 16.0 / 116.0; }

// A finite v rounded to the nearest level (halves up) and clamped to 0..255 (as std::lround, a
// call, but for the largest double below 0.5).
uint8_t Level(double v) {
  const double up = std::clamp(v, 0.0, 255.0) + 0.5;
  return static_cast<uint8_t>(up);  // NOLINT(bugprone-incorrect-roundings): see above
}

}  // namespace

void BgrToLab(const cv::Mat& bgr, cv::Mat* lab) {
  FV_REQUIRE(lab != nullptr, "BgrToLab: no output image");
  if (bgr.empty()) {
    lab->release();
    return;
  }
  FV_REQUIRE(bgr.type() == CV_8UC3, "BgrToLab: the image must be 8-bit BGR");
  FV_REQUIRE(lab->data == nullptr || lab->data != bgr.data, "BgrToLab: converting in place");
  const std::array<double, 256>& lin = LinearTable();
  lab->create(bgr.size(), CV_8UC3);
  for (int y = 0; y < bgr.rows; ++y) {
    const uint8_t* in = bgr.ptr<uint8_t>(y);
    uint8_t* out = lab->ptr<uint8_t>(y);
    for (int x = 0; x < bgr.cols; ++x, in += 3, out += 3) {
      const double b = lin[in[0]], g = lin[in[1]], r = lin[in[2]];
      // sRGB primaries to XYZ, divided by the D65 white point (OpenCV's matrix and white).
      const double fx = LabF((0.412453 * r + 0.357580 * g + 0.180423 * b) / 0.950456);
      const double fy = LabF(0.212671 * r + 0.715160 * g + 0.072169 * b);
      const double fz = LabF((0.019334 * r + 0.119193 * g + 0.950227 * b) / 1.088754);
      out[0] = Level((116.0 * fy - 16.0) * 255.0 / 100.0);
      out[1] = Level(500.0 * (fx - fy) + 128.0);
      out[2] = Level(200.0 * (fy - fz) + 128.0);
    }
  }
}

}  // namespace fv::detect
