// A file camera's background (detect/background.h) for its ball detector, built on first need
// (or from Start): BackgroundOptions::samples frames evenly across the video's first window_s
// seconds, read in order by a source of its own. Motion-JPEG videos and image files skip the
// frames between samples without decoding (io::FrameSource::SkipFrame); H.264 and the like decode
// each frame up to the last sample once (a seek would decode from the key frame before each
// sample: nearly the whole window per sample with most encoders' key-frame intervals), so they
// are sampled over a shorter window (decoded_window_s). On a video longer than the window, a
// later change of light makes the rings around balls differ too, and the colour checks alone
// decide there.
#pragma once

#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "fieldvision/camera/camera.h"
#include "fieldvision/detect/background.h"
#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/io/frame_source.h"

namespace fv::detect {

struct CameraBackgroundOptions {
  BackgroundOptions background;
  double window_s = 60.0;  // frames sampled from the video's first this many seconds
  // Videos that decode every frame they pass (H.264 and the like): sampled from the first this
  // many seconds at most (each decoded once more than the job itself does; the kick render as
  // H.264, 3.2 s of 4 cameras: see README); 0: no background for them.
  double decoded_window_s = 10.0;
  void Check() const;  // throws fv::Error naming the bad field
};

// The samples of a freshly opened `source` (FrameCount known), each reached by reading on in order
// (SkipFrame: without decoding where the source can) and reduced by `scale` (Background::Reduce);
// fewer than requested when the video is short, a sample cannot be decoded (left out) or reached
// (the rest too), none without a frame count.
std::vector<cv::Mat> SampleFrames(io::FrameSource* source, int samples, double window_s, int scale);

class CameraBackground {
 public:
  // `spec`: the camera's video (io::OpenFrameSource), opened again when the background is needed.
  CameraBackground(std::string spec, const CameraBackgroundOptions& options);
  // Starts building the background on a thread of its own (Get waits for it): a job that will
  // need it soon builds it while it opens its inputs.
  void Start();
  // The background, built on the first call unless started (thread-safe); null when the video
  // has too few frames, cannot be read again, or its frames disagree (a moving camera, changing
  // light).
  const Background* Get();
  // The detector's BackgroundFn for this camera (holds `self`).
  static BackgroundFn FnFor(std::shared_ptr<CameraBackground> self);
  // One line: what was built, or why none was, or kNotNeeded.
  std::string Summary() const;
  static constexpr const char* kNotNeeded = "no background needed";

 private:
  void Build();  // once; later calls wait for the first
  std::string spec_;
  CameraBackgroundOptions options_;
  mutable std::mutex mutex_;
  bool tried_ = false;
  bool used_ = false;  // Get was called
  std::optional<Background> background_;
  int sampled_ = 0;
  bool decoded_ = false;  // sampled in order, every frame up to the last sample decoded
  std::string why_none_;
  std::future<void> started_;  // last: a running build ends before the members go
};

// For a video of a posed (static) camera, when `on`: its background, set as `detector`'s (a
// BallDetector or AnyBallDetector); else null.
template <typename Detector>
std::shared_ptr<CameraBackground> UseCameraBackground(bool on, const std::string& video,
                                                      const camera::Camera* camera,
                                                      Detector* detector,
                                                      const CameraBackgroundOptions& options = {}) {
  if (!on || camera == nullptr || !camera->has_pose) return nullptr;
  auto background = std::make_shared<CameraBackground>(video, options);
  detector->SetBackground(CameraBackground::FnFor(background));
  return background;
}
// CameraBackground::Summary when it was needed, else "".
inline std::string NeededBackgroundSummary(const std::shared_ptr<CameraBackground>& background) {
  if (background == nullptr) return "";
  const std::string s = background->Summary();
  return s == CameraBackground::kNotNeeded ? "" : s;
}

}  // namespace fv::detect
