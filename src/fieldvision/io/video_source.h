// The frame-by-frame view of a frame source (io/frame_source.h, which does the reading) that the
// detection, colour, overlay and studio code use: a video file (its container's times), an image
// sequence (a printf pattern such as dir/%05d.png, a glob such as dir/*.jpg, or a folder of
// images, in name order, at options.fps) or any live source ("camera:0", "v4l2:...", "synth:..."
// with system-clock times). Frames are numbered from 0. Also the helpers the file backends share.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/camera/camera.h"

namespace fv::io {

struct VideoSourceOptions {
  // Frame rate of image sequences, which have none of their own; 0: the `fps` of a synth
  // scene.json beside them (or one folder up), else 30 stands in (FrameSource::rate_known).
  double fps = 0.0;
  void Check() const;
};

struct Frame {
  int index = -1;
  double time_s = 0.0;
  cv::Mat bgr;
};

class VideoSource {
 public:
  // Opens `spec`; throws fv::Error naming it when it cannot be opened or holds no frame.
  static std::unique_ptr<VideoSource> Open(const std::string& spec,
                                           const VideoSourceOptions& options = {});
  virtual ~VideoSource() = default;

  const std::string& spec() const { return spec_; }
  int width() const { return width_; }
  int height() const { return height_; }
  double fps() const { return fps_; }
  // False for an image sequence without a frame rate: fps() is a stand-in
  // (FrameSource::rate_known).
  bool rate_known() const { return rate_known_; }
  // Frames announced by the container or found on disk; -1 when unknown (live camera).
  int frame_count() const { return frame_count_; }
  bool live() const { return live_; }
  // FrameSource::FramesNote of the source behind it ("" for none).
  virtual std::string frames_note() const { return ""; }

  // Reads the next frame into `frame`; false at the end. A frame that cannot be decoded in an
  // image sequence, or a frame of another size, throws fv::Error naming the source and frame.
  virtual bool Read(Frame& frame) = 0;
  // Frames read so far.
  int frames_read() const { return next_index_; }

  // The camera fitted to the frames (camera::FitCameraToFrames: a note when an encoder's block
  // padding was taken off, "" when the sizes match); throws naming both files otherwise.
  std::string FitCamera(camera::Camera& camera, const std::string& camera_file) const;

 protected:
  std::string spec_;
  int width_ = 0;
  int height_ = 0;
  double fps_ = 0.0;
  bool rate_known_ = true;
  int frame_count_ = -1;
  bool live_ = false;
  int next_index_ = 0;
};

// The image files an image-sequence spec names, in order (empty if it is not one); an existing
// image file (by its extension) is a sequence of one.
std::vector<std::string> ListImageSequence(const std::string& spec);
// Whether `spec` names still photos (a folder, a glob, one image file) rather than a camera's
// frames (a video file, a stream, a numbered sequence dir/%05d.png).
bool IsStillImageInput(const std::string& spec);
// At the end of a video file: throws fv::Error naming it when fewer frames were read than its
// header announces (a truncated or damaged stream; 0 or less: not announced, nothing checked).
void CheckEndOfStream(const std::string& path, long long frames_read, long long frames_announced);
// Whether a path names an image file OpenCV reads, by its extension (case-insensitive).
bool IsImageFile(const std::string& path);

}  // namespace fv::io
