// Frame sources of the camera stages: a video file or image pattern read with cv::VideoCapture,
// with the capture time of each frame from the frame rate, the container's timestamps or a CSV
// of `frame,time_s` per video. The first frame is read when opening, so the frame size is known
// (and checked against the camera file) before any work starts.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/pipeline/jpeg_region.h"

namespace fv {

// A frame as a source delivers it: decoded (bgr) or, from a source that keeps frames encoded,
// the JPEG bytes for the camera stage to decode in full or only around the ball.
struct SourceFrame {
  cv::Mat bgr;                // empty when `jpeg` holds the frame
  std::vector<uint8_t> jpeg;  // an encoded JPEG frame, or empty
  long long frame = 0;
  double time_s = 0.0;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next frame (BGR), its number and capture time; false at the end of the stream.
  virtual bool Read(cv::Mat* bgr, long long* frame, double* time_s) = 0;
  // The next frame, encoded when the source can keep it so (default: decoded, as Read).
  virtual bool ReadFrame(SourceFrame* out) {
    out->jpeg.clear();
    return Read(&out->bgr, &out->frame, &out->time_s);
  }
  // Frames in the stream, or -1 when unknown.
  virtual long long FrameCount() const { return -1; }
  virtual cv::Size FrameSize() const = 0;
  virtual std::string name() const = 0;
};

enum class TimeSource { kFrameRate, kContainer, kCsv };

struct FrameSourceOptions {
  TimeSource time = TimeSource::kFrameRate;
  std::string timestamps_csv;  // kCsv: a file with columns frame,time_s
  double fps = 0.0;            // kFrameRate: 0 takes the container's rate (30 if it has none)
  // Motion-JPEG video or a pattern of JPEG files (dir/%05d.jpg): ReadFrame delivers the encoded
  // frames (SourceFrame::jpeg) so that a camera stage can decode only where the ball is; other
  // videos are decoded as usual.
  bool encoded = false;
  void Check() const;  // throws fv::Error naming the bad field
};

class VideoFrameSource : public FrameSource {
 public:
  // Opens `path` (a file OpenCV reads or a pattern such as dir/%05d.jpg) and reads its first
  // frame; throws fv::Error naming the file when it cannot be opened, is empty or the timestamps
  // cannot be read.
  explicit VideoFrameSource(const std::string& path, const FrameSourceOptions& options = {});
  bool Read(cv::Mat* bgr, long long* frame, double* time_s) override;
  bool ReadFrame(SourceFrame* out) override;
  // True when frames are delivered encoded (options.encoded and a Motion-JPEG video).
  bool encoded() const { return encoded_; }
  long long FrameCount() const override { return frame_count_; }
  cv::Size FrameSize() const override { return size_; }
  std::string name() const override { return path_; }
  double fps() const { return fps_; }

 private:
  bool Grab(cv::Mat* bgr, double* time_s);
  bool GrabFrame(SourceFrame* out);
  double TimeOf(long long frame);
  std::string path_;
  FrameSourceOptions options_;
  cv::VideoCapture capture_;
  std::map<long long, double> times_;  // kCsv
  bool encoded_ = false;
  bool jpeg_files_ = false;    // encoded: a pattern of JPEG files (else MJPG packets)
  long long first_file_ = -1;  // index of the first file of the pattern
  JpegRegionDecoder decoder_;  // Read() of an encoded stream
  SourceFrame pending_frame_;  // encoded: the first frame, read when opening
  cv::Mat pending_;            // the first frame, read when opening
  double pending_time_s_ = 0.0;
  bool has_pending_ = false;
  long long next_frame_ = 0;
  long long frame_count_ = -1;
  double fps_ = 30.0;
  cv::Size size_;
};

}  // namespace fv
