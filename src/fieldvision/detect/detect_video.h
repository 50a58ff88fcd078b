// `fieldvision detect`: runs the ball detector of one camera over a video (any file OpenCV reads
// or an image sequence, via fv::io::VideoSource), writes every candidate per frame to a CSV file
// and optionally draws them on the frames (an annotated video or a folder of images).
#pragma once

#include <functional>
#include <string>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/dnn_ball.h"

namespace fv::detect {

struct DetectVideoOptions {
  std::string camera;  // camera YAML; "" for an uncalibrated camera (no size check, no mask)
  std::string video;   // file or image pattern (dir/%05d.png)
  std::string out;     // CSV: frame,u,v,radius_px,score,accepted,sigma_px
  std::string field;   // built-in field name or JSON for the field mask; "" for none
  // "" none; *.avi / *.mp4 / *.mkv an annotated video (io/video_writer.h: H.264 in MP4 where
  // OpenCV's FFmpeg has it, else Motion-JPEG, a .mp4 path becoming .avi); else a folder of JPEGs
  std::string draw;
  int max_frames = -1;  // -1: all
  bool progress = true;
  // Called once the inputs are open and the outputs checked, before the first frame ("": none).
  std::function<void()> on_start;
  BallDetectorOptions detector;
  DnnBallOptions dnn;  // --detector colour|dnn|both (dnn_ball.h)
  // A video from a posed (static) camera: low-contrast candidates are compared with its
  // background (camera_background.h).
  bool background = true;
  // Throws fv::Error naming the bad field.
  void Check() const;
};

struct DetectVideoResult {
  int frames = 0;
  long long candidates = 0;
  int frames_with_ball = 0;  // frames with an accepted candidate
  double seconds = 0.0;
  std::string drawn;  // what --draw wrote (the video's path, frames and codec), "" when nothing
  std::string background;   // CameraBackground::Summary, "" when none was set up
  std::string frames_note;  // what the frame source did to the frames (FramesNote), or ""
  std::string Summary() const;
};

DetectVideoResult DetectVideo(const DetectVideoOptions& options);

// Draws candidates on a BGR frame: accepted in green (circle, centre cross, score), rejected in
// red (thin circle).
void DrawCandidates(cv::Mat& bgr, const std::vector<BallCandidate>& candidates);

// Lines of white text on a black band `width` px wide, each wrapped at spaces to fit.
cv::Mat TextBand(const std::vector<std::string>& text, int width);

// What DrawCandidates' colours and the off-field check's edge mean, as a TextBand (below each
// frame `detect --draw` writes).
cv::Mat CandidateLegend(int width);

}  // namespace fv::detect
