// Writing a video that plays where users look at it: H.264 in MP4 when the path ends in .mp4 and
// OpenCV's FFmpeg has the encoder (browsers play it), else Motion-JPEG (a .mp4 path then becomes
// .avi; .avi and .mkv keep their container). Frames go to a temporary file beside the path
// (util::AtomicOutput: through a symlink, never onto a folder), renamed to it by Close(): a run
// that fails leaves an existing file as it was. OpenCV's own log
// lines about a missing encoder are kept from the terminal (an expected outcome here).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/util/output_path.h"

namespace fv::io {

class PlayableVideoWriter {
 public:
  // Throws fv::Error naming the path when it is no video's name (CheckVideoPath), no writer
  // opens, the frame rate is not positive or the size is empty.
  // `what` names the path in errors (an option such as "--draw").
  PlayableVideoWriter(const std::string& path, double fps, cv::Size size,
                      std::string_view what = "video");
  ~PlayableVideoWriter();  // without Close(): the temporary file is removed
  PlayableVideoWriter(const PlayableVideoWriter&) = delete;
  PlayableVideoWriter& operator=(const PlayableVideoWriter&) = delete;
  // Throws fv::Error naming the path for a frame of another size or type than CV_8UC3.
  void Write(const cv::Mat& bgr);
  // Finishes the file and renames it to path(); throws fv::Error naming it when that fails.
  void Close();
  const std::string& path() const { return path_; }    // the file written (extension may change)
  const std::string& codec() const { return codec_; }  // "H.264" or "MJPG"
  const std::string& note() const { return note_; }    // why MJPG for a .mp4 path, when it is
  int frames() const { return frames_; }

 private:
  std::unique_ptr<cv::VideoWriter> writer_;  // made by the codecs plugin
  std::unique_ptr<util::AtomicOutput> out_;  // the temporary file beside path_
  std::string path_, codec_, note_;
  cv::Size size_;
  int frames_ = 0;
  bool closed_ = false;
};

// Whether OpenCV's FFmpeg backend can write H.264 MP4 here (tried once on a tiny file).
bool H264Available();

// Whether the path ends in .mp4, .avi or .mkv (any case): the writer picks the container by it.
bool IsVideoName(const std::string& path);
// Throws fv::Error naming `what` and `path` unless IsVideoName: another name (an image, a
// pattern) would be written as something else or fail at the end of a run.
void CheckVideoPath(const std::string& path, std::string_view what);
// The file a writer of `path` writes where OpenCV has no H.264 encoder: a .mp4 path as .avi, any
// other as it is (callers check it against their inputs too).
std::string FallbackVideoPath(const std::string& path);
// The checks of a video output before a run, naming `what`: a video's name (CheckVideoPath),
// neither it nor its FallbackVideoPath one of `inputs` (CheckOutputPath), not a folder or a
// device (ResolveOutputPath).
void CheckVideoOutput(const std::string& path, const std::vector<std::string>& inputs,
                      std::string_view what);

}  // namespace fv::io
