// Frames whose chroma the decoder repeated over 2x2 pixels, re-upsampled. OpenCV's FFmpeg reader
// converts 4:2:0 video (H.264, MPEG-4, HEVC, most cameras' and phones' files and streams) to BGR
// through swscale's unscaled path, which gives each chroma sample to its 2x2 pixels: colour edges
// then lie on a 2-pixel grid and a ball's outline, which is mostly a colour edge on grass, moves
// by up to a pixel with its position on that grid. Each pixel keeps its luma and takes a weighted
// mean of the chroma of the four blocks around it: the bilinear weight (samples at the blocks'
// centres, as JPEG, MPEG-1 and swscale's decimation site them) times a range weight on the
// difference between the pixel's luma and the block's (joint bilateral upsampling, Kopf et al.,
// SIGGRAPH 2007), so colour follows the full-resolution luma edges. Chroma is taken as BGR minus
// luma (a decoder's YCbCr -> RGB adds luma to every channel alike).
#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace fv::io {

struct RepeatedChromaOptions {
  // Range weight exp(-dL^2 / (2 sigma^2)) on the luma difference (0..255) between a pixel and a
  // block. Measured on the kick rendered as H.264 and read by OpenCV, the frames re-upsampled
  // offline (`ball`'s 3D mean error; as decoded 2.98 mm): bilinear (sigma infinite) 1.96, sigma 4
  // 1.83, 8 1.51, 16 1.56 mm; per-view 2D median on it and the low-sun kick, as decoded 0.309 /
  // 0.532 px, sigma 8 0.222 / 0.474, 16 0.209 / 0.439 px.
  double luma_sigma = 12.0;
  // Pixels of blocks whose chroma ranges over at most skip_levels (the ranges of B, G and R minus
  // luma summed) across the block and its eight neighbours are kept: there every weight falls on
  // about one chroma. Most of a frame (grass, sky, walls) is such blocks: 78-84 % of a decoded
  // 1280x960 kick frame.
  double skip_levels = 8.0;
  // A frame's chroma is repeated when its mean change between a block's pixels is at most
  // max_within_share of its mean change between neighbouring blocks, and the latter at least
  // min_across (BGR-minus-luma units): a frame of one colour says nothing.
  double max_within_share = 0.2;
  double min_across = 0.3;
  void Check() const;  // throws fv::Error naming the bad field
};

enum class ChromaLayout { kUnknown, kRepeated2x2, kOther };

// Whether `bgr`'s chroma is repeated over aligned 2x2 blocks (every fourth block row measured).
ChromaLayout MeasureChromaLayout(const cv::Mat& bgr, const RepeatedChromaOptions& options = {});

// Buffers of UpsampleRepeatedChroma, kept between a stream's frames (allocating them for each
// frame costs more than the work: fresh pages fault in).
struct ChromaWorkspace {
  cv::Mat padded, luma, block_bgr, block_luma, block_luma3, block_chroma, hi, lo, edge;
};

// Re-upsamples the chroma of a frame whose chroma is repeated over 2x2 blocks (8-bit BGR, any
// size; a last odd row or column is a block of its own). In place.
void UpsampleRepeatedChroma(cv::Mat* bgr, const RepeatedChromaOptions& options = {});
void UpsampleRepeatedChroma(cv::Mat* bgr, const RepeatedChromaOptions& options,
                            ChromaWorkspace* workspace);

// A stream's frames: the layout is measured on each frame until one decides it (at most
// kMeasuredFrames: a stream without colour in them, grey video, is left as it is), then every
// frame of a stream with repeated chroma is re-upsampled.
class RepeatedChromaRepair {
 public:
  explicit RepeatedChromaRepair(const RepeatedChromaOptions& options = {});
  void Apply(cv::Mat* bgr);
  ChromaLayout layout() const { return layout_; }
  // A line for a summary when the stream's chroma is re-upsampled, else "".
  std::string Note() const;
  static constexpr int kMeasuredFrames = 30;

 private:
  RepeatedChromaOptions options_;
  ChromaWorkspace workspace_;
  ChromaLayout layout_ = ChromaLayout::kUnknown;
  int measured_ = 0;
};

}  // namespace fv::io
