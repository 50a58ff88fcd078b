// Helpers shared by the io tests and those above them (header only, not part of the library): a
// video file cut short, a JPEG header that announces another size, chroma as FFmpeg's reader
// repeats it.
#pragma once

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace fv::io::test_util {

// Rewrites the size in a baseline JPEG's SOF0 segment (FF C0, length, precision, height, width,
// big-endian), leaving the data as it is; false when there is no SOF0 segment.
inline bool SetJpegHeaderSize(std::vector<uint8_t>* jpeg, int width, int height) {
  for (size_t i = 2; i + 8 < jpeg->size(); ++i) {
    if ((*jpeg)[i] != 0xFF || (*jpeg)[i + 1] != 0xC0) continue;
    (*jpeg)[i + 5] = static_cast<uint8_t>(height >> 8);
    (*jpeg)[i + 6] = static_cast<uint8_t>(height & 0xFF);
    (*jpeg)[i + 7] = static_cast<uint8_t>(width >> 8);
    (*jpeg)[i + 8] = static_cast<uint8_t>(width & 0xFF);
    return true;
  }
  return false;
}

// A 16-frame 320x240 MJPG video at 25 fps cut to `keep` of its bytes (the header still announces
// 16 frames); returns `path`.
inline std::string WriteTruncatedMjpg(const std::string& path, double keep) {
  {
    // Noisy frames: JPEGs large against the container's header, so a cut lands in the frames.
    cv::VideoWriter w(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0, cv::Size(320, 240));
    cv::RNG rng(7);
    for (int i = 0; i < 16; ++i) {
      cv::Mat m(240, 320, CV_8UC3);
      rng.fill(m, cv::RNG::UNIFORM, 0, 256);
      w.write(m);
    }
  }
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      << bytes.substr(0, static_cast<size_t>(keep * bytes.size()));
  return path;
}

// What OpenCV's FFmpeg reader makes of 4:2:0 video: each 2x2 block takes its mean chroma (the
// encoder's decimation) and every pixel of the block gets it (the decoder's, swscale's unscaled
// conversion).
inline cv::Mat RepeatChroma2x2(const cv::Mat& bgr) {
  cv::Mat ycc;
  cv::cvtColor(bgr, ycc, cv::COLOR_BGR2YCrCb);
  cv::Mat half, full;
  cv::resize(ycc, half, cv::Size(ycc.cols / 2, ycc.rows / 2), 0, 0, cv::INTER_AREA);
  cv::resize(half, full, ycc.size(), 0, 0, cv::INTER_NEAREST);
  const int from_to[] = {1, 1, 2, 2};
  cv::mixChannels(&full, 1, &ycc, 1, from_to, 2);
  cv::Mat out;
  cv::cvtColor(ycc, out, cv::COLOR_YCrCb2BGR);
  return out;
}

}  // namespace fv::io::test_util
