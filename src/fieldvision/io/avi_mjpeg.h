// Motion-JPEG AVI files read directly: the JPEG frames are the video stream's chunks in the RIFF
// 'movi' lists (AVI 1.0, and the OpenDML 'AVIX' extensions of files over 1 GB), read in file
// order; the frame rate and count come from the stream header (strh). After the AVI file format
// (Microsoft, "AVI RIFF File Reference"; OpenDML AVI File Format Extensions 1.02). Written here
// because opening an AVI through OpenCV costs loading its video I/O (codecs.h), a tenth of a
// second of `fieldvision ball`; any other file, or an AVI this does not parse, goes to OpenCV.
#pragma once

#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

namespace fv::io {

class AviMjpegReader {
 public:
  // The reader of `path` when it is an AVI whose first video stream is Motion-JPEG, else nullptr
  // (not an AVI, another codec, headers this does not understand). Never throws for bad data.
  static std::unique_ptr<AviMjpegReader> Open(const std::string& path);

  // The next frame's JPEG data; false at the end of the stream or where the file is cut short.
  bool Next(std::vector<uint8_t>* jpeg);

  double fps() const { return fps_; }                // 0 when the headers give none
  long long frame_count() const { return frames_; }  // as the headers announce, -1 unknown
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  AviMjpegReader() = default;
  bool ReadHeaders();
  bool ReadStreamList(uint64_t end, int index);

  std::ifstream in_;
  uint64_t file_size_ = 0;
  uint32_t video_chunk_dc_ = 0, video_chunk_db_ = 0;  // "NNdc", "NNdb" of the video stream
  bool have_video_ = false;
  double fps_ = 0;
  long long frames_ = -1;
  int width_ = 0, height_ = 0;
  double avih_fps_ = 0;  // from the main header's frame period: the fallback
  long long avih_frames_ = -1;
};

}  // namespace fv::io
