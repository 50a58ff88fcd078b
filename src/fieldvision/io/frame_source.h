// Frame sources behind one interface, chosen by the spec's form, one backend per file:
//   dir/*.png, a folder of images (name order),     image_list_source.cc (frame rate or CSV;
//   dir/%05d.jpg from one of 0..1000                 JPEG files kept encoded on request)
//   a video file (or another image pattern)          file_source.cc (timestamps from the frame
//                                                    rate, the container or a CSV; Motion-JPEG
//                                                    kept encoded on request)
//   v4l2:/dev/videoN, camera:N                       v4l2_source.cc (kernel buffer timestamps)
//   gst:PIPELINE, rtsp://...                         gstreamer_source.cc (stream timestamps)
//   aravis:[DEVICE-ID]                               aravis_source.cc (GigE / USB3 Vision; only
//                                                    when built with libaravis-dev)
//   synth:PRESET_OR_SCENE.json?camera=NAME&...       synth_source.cc (a synth scene played live)
// A file played with `realtime` (paced_source.cc) is delivered at its own frame rate as a live
// camera would be: frames wait in a small buffer and the oldest are dropped when the reader is
// slower. Each frame carries its capture time and says where that time came from (TimeOrigin);
// times of live sources are seconds on this machine's system clock (Unix time), times of files
// read as fast as possible are the video's own (from 0). Frames OpenCV decodes with their chroma
// repeated over 2x2 pixels (FFmpeg's 4:2:0 video, as H.264 and MPEG-4) come re-upsampled
// (repeated_chroma.h).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/io/jpeg_region.h"

namespace fv::io {

// Where a frame's time_s comes from.
enum class TimeOrigin {
  kFrameRate,  // frame / fps (files)
  kContainer,  // the container's or stream's timestamps
  kCsv,        // a frame,time_s CSV
  kDevice,     // the capture device (V4L2 buffer, GenICam timestamp), on the system clock
  kPlayback,   // a file or scene played live: the frame's scheduled capture instant
  kArrival,    // when the frame reached this program (no better time known)
};
const char* ToString(TimeOrigin origin);

// A frame as a source delivers it: decoded (bgr) or, from a source that keeps frames encoded,
// the JPEG bytes for the camera stage to decode in full or only around the ball.
struct SourceFrame {
  cv::Mat bgr;                // empty when `jpeg` holds the frame
  std::vector<uint8_t> jpeg;  // an encoded JPEG frame, or empty
  long long frame = 0;        // from 0 in the stream
  double time_s = 0.0;        // capture time
  TimeOrigin origin = TimeOrigin::kFrameRate;
};

enum class TimeSource { kFrameRate, kContainer, kCsv };  // files: where time_s comes from

struct FrameSourceOptions {
  TimeSource time = TimeSource::kFrameRate;
  std::string timestamps_csv;  // kCsv: a file with columns frame,time_s
  double fps = 0.0;  // files: 0 takes the container's rate (30 if none); live: requested rate
  // Motion-JPEG video, a pattern of JPEG files or a synth scene: ReadFrame delivers encoded
  // frames (SourceFrame::jpeg) so that a camera stage can decode only where the ball is.
  bool encoded = false;
  // Files: delivered at their own frame rate from start_at_s (Unix seconds on the system clock;
  // 0: the first read), stamped with each frame's scheduled capture time. Synth scenes always are.
  bool realtime = false;
  double start_at_s = 0.0;
  int live_buffer_frames = 4;  // frames a live source holds for a slow reader (oldest dropped)
  // Live cameras: requested image size (0: the device's), exposure (0: automatic) and, for
  // Aravis, the trigger source ("" free-running, "Software", "Line1", ...).
  int width = 0, height = 0;
  double exposure_us = 0.0;
  std::string trigger;
  void Check() const;  // throws fv::Error naming the bad field
};

// The frame,time_s file of TimeSource::kCsv, frame -> time_s. Throws fv::Error naming file and
// line for a frame below 0 or listed twice, a time that is not a number in [0, kMaxTimestampS] or
// one that does not increase with the frame.
inline constexpr double kMaxTimestampS = 1e10;  // Unix seconds until the year 2286
std::map<long long, double> ReadTimestampsCsv(const std::string& path);

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next frame, encoded when the source keeps it so (options.encoded); false at the end of
  // the stream. Throws fv::Error naming the source when it fails (a camera that disappears).
  virtual bool ReadFrame(SourceFrame* out) = 0;
  // Skips the next frame without decoding it where the source can; false at the end.
  virtual bool SkipFrame();
  // Positions a file or image sequence so that the next ReadFrame returns `frame` (at or after
  // the next frame), decoding as little as the format allows: Motion-JPEG and image files skip
  // without decoding, other codecs seek to the key frame before it (OpenCV's FFmpeg backend) and
  // decode from there (where a container's index is approximate, an MPEG-TS, a few frames early).
  // False when the source cannot (live) or `frame` lies beyond its end.
  virtual bool SeekFrame(long long frame);
  // Whether skipping and seeking go without decoding (Motion-JPEG packets, image files).
  virtual bool SkipsWithoutDecoding() const { return false; }
  // The next frame decoded to BGR, its number and capture time; false at the end.
  bool Read(cv::Mat* bgr, long long* frame, double* time_s);
  // Frames in the stream, or -1 when unknown (live).
  virtual long long FrameCount() const { return -1; }
  virtual cv::Size FrameSize() const = 0;
  virtual std::string name() const = 0;
  virtual double fps() const = 0;
  // False when the frames have no rate of their own (an image sequence, a video whose container
  // gives none) and none was given (FrameSourceOptions::fps, a timestamps CSV): fps() is then a
  // stand-in (30) that times must not be taken from.
  virtual bool rate_known() const { return true; }
  // True for live sources (cameras, streams, played files): time_s is on the system clock.
  virtual bool live() const { return false; }
  // True when ReadFrame delivers encoded frames.
  virtual bool encoded() const { return false; }
  // Frames the source skipped because the reader was slower than the camera.
  virtual long long dropped() const { return 0; }
  // What the source does to its frames beyond decoding, for a job's summary ("" for nothing):
  // chroma the decoder repeated, re-upsampled (repeated_chroma.h).
  virtual std::string FramesNote() const { return ""; }

 private:
  JpegRegionDecoder decoder_;  // Read() of encoded frames
};

// Opens `spec` (see the table above); throws fv::Error naming it when the scheme is unknown, the
// backend is not built in, or the source cannot be opened or holds no frame.
std::unique_ptr<FrameSource> OpenFrameSource(const std::string& spec,
                                             const FrameSourceOptions& options = {});

// The camera fitted to the source's frames (camera::FitCameraToFrames: a note when an encoder's
// block padding was taken off, "" when the sizes match); throws naming both otherwise.
std::string FitCameraToSource(const FrameSource& source, camera::Camera& camera,
                              const std::string& camera_file);

// Seconds on the system clock (Unix time): the clock of live sources' time_s.
double SystemClockNow();

// Names of the live backends compiled in ("v4l2", "gstreamer", "aravis", "synth").
std::vector<std::string> FrameSourceBackends();

}  // namespace fv::io
