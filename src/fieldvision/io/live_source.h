// OpenCV captures and what the live backends share (internal to io): every cv::VideoCapture of
// the project is opened here (OpenVideoFile, OpenCapture); LiveSource delivers the frame read
// when opening first and numbers frames from 0.
#pragma once

#include <string>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/io/frame_source.h"
#include "fieldvision/io/repeated_chroma.h"

namespace fv::io::backend {

class LiveSource : public FrameSource {
 public:
  bool ReadFrame(SourceFrame* out) override;
  cv::Size FrameSize() const override { return size_; }
  std::string name() const override { return spec_; }
  double fps() const override { return fps_; }
  bool live() const override { return true; }

 protected:
  // `noun` names the source in errors ("camera", "stream"); a stream that `may_end` ends
  // ReadFrame with false, else a source that stops delivering is an error (disconnected).
  LiveSource(std::string spec, std::string noun, bool may_end);
  // Reads the first frame (from a subclass' constructor); throws "<noun> '<spec>' delivers no
  // frame" when none comes.
  void ReadFirstFrame();
  // The next frame as BGR with its time; false when none comes.
  virtual bool Grab(SourceFrame* out) = 0;
  const std::string& spec() const { return spec_; }
  double fps_ = 30.0;

 private:
  std::string spec_, noun_;
  bool may_end_ = false;
  SourceFrame pending_;
  bool has_pending_ = false;
  long long next_ = 0;
  cv::Size size_;
};

// Opens a video file, or a printf image pattern (dir/%05d.jpg), with FFmpeg or OpenCV's image
// reader, never GStreamer, whose failure on a file that is not a video prints pages of GLib
// warnings. False when it cannot be opened.
bool OpenVideoFile(cv::VideoCapture& capture, const std::string& path);
// Opens `target` with the OpenCV backend `api` (cv::CAP_V4L2, cv::CAP_GSTREAMER); false, never
// an exception, when it cannot.
bool OpenCapture(cv::VideoCapture& capture, const std::string& target, int api);
// The next frame of `capture` as BGR (grey converted; chroma the decoder repeated over 2x2
// pixels re-upsampled by `chroma`, repeated_chroma.h), its arrival on the system clock and the
// capture's position in milliseconds (CAP_PROP_POS_MSEC: the buffer's timestamp); false at the
// end or on a read error.
bool ReadCapture(cv::VideoCapture& capture, RepeatedChromaRepair* chroma, SourceFrame* out,
                 double* arrival_s, double* pos_ms);

}  // namespace fv::io::backend
