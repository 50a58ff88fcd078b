#include "fieldvision/io/repeated_chroma.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"

namespace fv::io {
namespace {

// Sum over the channels of |chroma(a) - chroma(b)|, chroma = BGR - luma (la, lb).
inline int ChromaStep(const cv::Vec3b& a, int la, const cv::Vec3b& b, int lb) {
  return std::abs((a[0] - la) - (b[0] - lb)) + std::abs((a[1] - la) - (b[1] - lb)) +
         std::abs((a[2] - la) - (b[2] - lb));
}

// Per 2x2 block of an even-sized frame: the mean chroma (BGR - luma, CV_16SC3) and the mean luma
// (CV_8U), by OpenCV's area resampling (each mean rounded to a level), into `ws` (reused: a
// stream's buffers are allocated once).
void BlockMeans(const cv::Mat& bgr, ChromaWorkspace* ws) {
  const cv::Size half(bgr.cols / 2, bgr.rows / 2);
  cv::resize(bgr, ws->block_bgr, half, 0, 0, cv::INTER_AREA);
  cv::resize(ws->luma, ws->block_luma, half, 0, 0, cv::INTER_AREA);
  cv::cvtColor(ws->block_luma, ws->block_luma3, cv::COLOR_GRAY2BGR);
  cv::subtract(ws->block_bgr, ws->block_luma3, ws->block_chroma, cv::noArray(), CV_16SC3);
}

// Blocks where the chroma's range over the block and its 8 neighbours, summed over the
// channels, exceeds `levels`: only their pixels change (elsewhere every weight falls on about
// one chroma). Into ws->edge.
void ChromaEdgeBlocks(double levels, ChromaWorkspace* ws) {
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  cv::dilate(ws->block_chroma, ws->hi, kernel);
  cv::erode(ws->block_chroma, ws->lo, kernel);
  const int rows = ws->block_chroma.rows, cols = ws->block_chroma.cols;
  ws->edge.create(rows, cols, CV_8U);
  const int limit = static_cast<int>(std::floor(levels));
  for (int j = 0; j < rows; ++j) {
    const cv::Vec3s* const hi = ws->hi.ptr<cv::Vec3s>(j);
    const cv::Vec3s* const lo = ws->lo.ptr<cv::Vec3s>(j);
    uint8_t* __restrict const e = ws->edge.ptr<uint8_t>(j);
    for (int i = 0; i < cols; ++i) {
      const int range = (hi[i][0] - lo[i][0]) + (hi[i][1] - lo[i][1]) + (hi[i][2] - lo[i][2]);
      e[i] = range > limit ? 1 : 0;
    }
  }
}

}  // namespace

void RepeatedChromaOptions::Check() const {
  FV_REQUIRE(std::isfinite(luma_sigma) && luma_sigma > 0,
             "repeated chroma: luma_sigma must be > 0 (got {})", luma_sigma);
  FV_REQUIRE(std::isfinite(max_within_share) && max_within_share >= 0 && max_within_share < 1,
             "repeated chroma: max_within_share must be in [0, 1) (got {})", max_within_share);
  FV_REQUIRE(std::isfinite(skip_levels) && skip_levels >= 0,
             "repeated chroma: skip_levels must be >= 0 (got {})", skip_levels);
  FV_REQUIRE(std::isfinite(min_across) && min_across >= 0,
             "repeated chroma: min_across must be >= 0 (got {})", min_across);
}

ChromaLayout MeasureChromaLayout(const cv::Mat& bgr, const RepeatedChromaOptions& o) {
  o.Check();
  FV_REQUIRE(bgr.type() == CV_8UC3, "repeated chroma: the frame must be 8-bit BGR (got type {})",
             bgr.type());
  cv::Mat luma;  // the luma UpsampleRepeatedChroma keeps (OpenCV's BT.601)
  cv::cvtColor(bgr, luma, cv::COLOR_BGR2GRAY);
  double within = 0, across = 0;
  long long pairs = 0;
  for (int y = 0; y + 2 < bgr.rows; y += 8) {  // every fourth block row
    const cv::Vec3b* r0 = bgr.ptr<cv::Vec3b>(y);
    const cv::Vec3b* r1 = bgr.ptr<cv::Vec3b>(y + 1);
    const cv::Vec3b* r2 = bgr.ptr<cv::Vec3b>(y + 2);
    const uint8_t* l0 = luma.ptr<uint8_t>(y);
    const uint8_t* l1 = luma.ptr<uint8_t>(y + 1);
    const uint8_t* l2 = luma.ptr<uint8_t>(y + 2);
    for (int x = 0; x + 2 < bgr.cols; x += 2) {
      within +=
          ChromaStep(r0[x], l0[x], r0[x + 1], l0[x + 1]) + ChromaStep(r0[x], l0[x], r1[x], l1[x]);
      across += ChromaStep(r0[x + 1], l0[x + 1], r0[x + 2], l0[x + 2]) +
                ChromaStep(r1[x], l1[x], r2[x], l2[x]);
      pairs += 2;
    }
  }
  if (pairs == 0) return ChromaLayout::kUnknown;
  within /= static_cast<double>(pairs);
  across /= static_cast<double>(pairs);
  if (across < o.min_across) return ChromaLayout::kUnknown;
  return within <= o.max_within_share * across ? ChromaLayout::kRepeated2x2 : ChromaLayout::kOther;
}

void UpsampleRepeatedChroma(cv::Mat* bgr, const RepeatedChromaOptions& o) {
  ChromaWorkspace ws;
  UpsampleRepeatedChroma(bgr, o, &ws);
}

void UpsampleRepeatedChroma(cv::Mat* bgr, const RepeatedChromaOptions& o, ChromaWorkspace* ws) {
  o.Check();
  FV_REQUIRE(bgr != nullptr && bgr->type() == CV_8UC3 && ws != nullptr,
             "repeated chroma: the frame must be 8-bit BGR");
  if (bgr->cols < 2 || bgr->rows < 2) return;
  // An odd last row or column: a block of its own, by padding to even size.
  const cv::Mat* even = bgr;
  if (bgr->cols % 2 != 0 || bgr->rows % 2 != 0) {
    cv::copyMakeBorder(*bgr, ws->padded, 0, bgr->rows % 2, 0, bgr->cols % 2, cv::BORDER_REPLICATE);
    even = &ws->padded;
  }
  cv::cvtColor(*even, ws->luma, cv::COLOR_BGR2GRAY);
  BlockMeans(*even, ws);
  ChromaEdgeBlocks(o.skip_levels, ws);
  const cv::Mat& luma = ws->luma;
  const cv::Mat& edge = ws->edge;
  const cv::Mat& block_luma = ws->block_luma;
  const cv::Mat& block_chroma = ws->block_chroma;
  std::array<float, 256> range{};
  for (int d = 0; d < 256; ++d) {
    range[d] = static_cast<float>(std::exp(-0.5 * d * d / (o.luma_sigma * o.luma_sigma)));
  }
  const int block_cols = block_luma.cols, block_rows = block_luma.rows;
  const int cols = bgr->cols, rows = bgr->rows;
  // The bilinear weights of the own block, the side neighbours towards the pixel and the corner.
  constexpr float kOwn = 9.f / 16, kSide = 3.f / 16, kCorner = 1.f / 16;
  for (int y = 0; y < rows; ++y) {
    const int j = y / 2;
    const int ny = std::clamp(j + ((y & 1) != 0 ? 1 : -1), 0, block_rows - 1);
    const uint8_t* const edge_row = edge.ptr<uint8_t>(j);
    const uint8_t* const lum_j = block_luma.ptr<uint8_t>(j);
    const uint8_t* const lum_n = block_luma.ptr<uint8_t>(ny);
    const cv::Vec3s* const cj = block_chroma.ptr<cv::Vec3s>(j);
    const cv::Vec3s* const cn = block_chroma.ptr<cv::Vec3s>(ny);
    const uint8_t* const l = luma.ptr<uint8_t>(y);
    cv::Vec3b* __restrict const p = bgr->ptr<cv::Vec3b>(y);
    for (int i = 0; i < (cols + 1) / 2; ++i) {
      if (edge_row[i] == 0) continue;
      // The block's pixels: the left one's side neighbour is the block to the left, the right
      // one's the block to the right.
      for (int x = 2 * i, side = -1; x < std::min(2 * i + 2, cols); ++x, side = 1) {
        const int nx = std::clamp(i + side, 0, block_cols - 1);
        const int lp = l[x];
        const float w0 = kOwn * range[std::abs(lp - lum_j[i])];
        const float w1 = kSide * range[std::abs(lp - lum_j[nx])];
        const float w2 = kSide * range[std::abs(lp - lum_n[i])];
        const float w3 = kCorner * range[std::abs(lp - lum_n[nx])];
        const float w_sum = w0 + w1 + w2 + w3;
        if (w_sum < 1e-6f) continue;  // no block of this luma near: keep the pixel
        const float inv = 1.f / w_sum;
        const cv::Vec3s &a0 = cj[i], &a1 = cj[nx], &a2 = cn[i], &a3 = cn[nx];
        const float lf = static_cast<float>(lp) + 0.5f;
        for (int ch = 0; ch < 3; ++ch) {
          const float v = lf + (w0 * a0[ch] + w1 * a1[ch] + w2 * a2[ch] + w3 * a3[ch]) * inv;
          p[x][ch] = static_cast<uint8_t>(std::clamp(v, 0.f, 255.f));  // rounded by the 0.5
        }
      }
    }
  }
}

RepeatedChromaRepair::RepeatedChromaRepair(const RepeatedChromaOptions& options)
    : options_(options) {
  options_.Check();
}

std::string RepeatedChromaRepair::Note() const {
  return layout_ == ChromaLayout::kRepeated2x2
             ? "colour repeated over 2x2 pixels by the video reader (4:2:0), re-upsampled along "
               "the luma's edges"
             : "";
}

void RepeatedChromaRepair::Apply(cv::Mat* bgr) {
  if (bgr == nullptr || bgr->empty() || bgr->type() != CV_8UC3) return;
  if (layout_ == ChromaLayout::kUnknown) {
    layout_ = MeasureChromaLayout(*bgr, options_);
    if (layout_ == ChromaLayout::kUnknown && ++measured_ >= kMeasuredFrames) {
      layout_ = ChromaLayout::kOther;
    }
  }
  if (layout_ == ChromaLayout::kRepeated2x2) UpsampleRepeatedChroma(bgr, options_, &workspace_);
}

}  // namespace fv::io
