// The camera stage of the ball pipeline: one camera's frames in, timestamped ball candidates out
// (CameraMessage). It tracks the ball in the image and searches a window around where it is
// expected (constant velocity in the image), decoding encoded frames (SourceFrame::jpeg) only
// there. When the window has no accepted candidate where the ball is expected, a guided fit
// (BallGuidedFn) looks for it at that place with its size (at most max_guided_frames frames in a
// row); when that fails too (another object took the window) and when the ball was not seen in
// the previous frame, the whole frame is searched. While tracking it looks for other balls too: the
// whole frame every full_scan_every frames, each camera at its own phase (from its name) so that
// the cameras of a rig do not all pay for it in the same frame; that search may be split into bands
// of rows, one a frame besides the window, for a lower peak of work per frame (a latency spike on a
// live node) at some more work on average (the bands overlap); after a whole-frame search without a
// ball at the expected place the guided fit is tried there too. With the fusion's hints
// (ball_hints.h) the expected place is where the cameras together last saw the ball, when the image
// track disagrees and was not on the ball in the frame they saw it in; a ball they see and this
// camera does not is hidden from it, and its whole frame is searched less often
// (hidden_scan_every). The same stage serves the in-process pipeline (ball_pipeline.h) and the
// camera node (net/node.h).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/io/frame_source.h"
#include "fieldvision/io/jpeg_region.h"
#include "fieldvision/pipeline/ball_hints.h"
#include "fieldvision/pipeline/camera_message.h"
#include "fieldvision/recon/triangulation.h"

namespace fv::pipeline {

// A camera stage's detector: the ball candidates of one BGR frame, best first. Called from that
// camera's thread only.
using BallDetectFn = std::function<std::vector<recon::BallObservation>(const cv::Mat& bgr)>;
// A detector that can search a region only (roi empty: the whole frame). Pixels of `bgr` outside
// roi may be stale and must not be read. Weak candidates are never tracked.
using BallRegionDetectFn =
    std::function<std::vector<recon::BallObservation>(const cv::Mat& bgr, const cv::Rect& roi)>;

// A ball of about `radius_px` at `centre_px` (a tracked ball's expected place), or nullopt; reads
// nothing of `bgr` outside roi (detect::BallDetector::FitAt).
using BallGuidedFn = std::function<std::optional<recon::BallObservation>(
    const cv::Mat& bgr, const cv::Rect& roi, const Eigen::Vector2d& centre_px, double radius_px)>;

// Ball tracking in each camera stage (see above).
struct BallTrackOptions {
  bool enabled = true;
  int full_scan_every = 20;  // while tracking, the whole frame is searched every N frames
  // In this many bands of rows (1..full_scan_every), one a frame in consecutive frames: the
  // frame's height / scan_bands, widened on both sides by 1.5 diameters of a ball twice the tracked
  // one's size plus 4 px, so that such a ball lies wholly inside some band with the detector's
  // margin. 1: the whole frame at once.
  int scan_bands = 1;
  double window_radii = 6.0;  // half-size of the window in ball radii, plus the image motion
  int min_window_px = 40;     // half-size of the window at least
  // Frames in a row that the track may go on by guided fits alone (0: no guided fits); then it
  // needs a ball the detector finds by itself.
  int max_guided_frames = 15;
  // With the in-process fusion's hints: while the cameras together have had no position for the
  // ball (no hint of at most BallHintOptions::max_age_s), a tracking camera searches the whole
  // frame once every this many frames (0: only every full_scan_every; camera nodes: never). A track
  // on a still ball-coloured thing that no other camera confirms gives way to the ball when it
  // comes into view (the kick render, cam1 and cam2: the ball hidden from cam1 until frame 19,
  // tracked from frame 33, the next whole-frame search, before).
  int unconfirmed_scan_every = 5;
  // With hints: while the cameras together follow the ball (a fused position at most
  // BallHintOptions::lag_messages + 1 frames old, on a line through three at least) where this
  // camera had no candidate in that frame, and it finds none where they expect it now, the ball
  // is hidden from this camera: it searches the whole frame only in the first of every this many
  // such frames in a row (0 or 1: in each), and its window where the others see the ball in each
  // (the kick render: cam1 searched 17 frames whole while the ball was behind a robot, now 5).
  int hidden_scan_every = 5;
  void Check() const;  // throws fv::Error naming the bad field
};

struct CameraStageStats {
  long long frames = 0;
  long long candidates = 0;    // accepted candidates reported
  long long full_scans = 0;    // frames searched whole
  long long window_scans = 0;  // frames searched in a window
  long long band_scans = 0;    // of these, also in a band of rows
  long long guided = 0;        // candidates from guided fits
  long long bad_frames = 0;    // encoded frames that could not be decoded
  std::string first_bad_frame;
};

// At least one candidate that is not weak.
bool HasAccepted(const std::vector<recon::BallObservation>& obs);

class CameraStage {
 public:
  // `camera_index` goes into the messages; `source_name` into errors; `guided` may be empty (no
  // guided fits). Throws fv::Error when the detector is empty or the options are bad.
  CameraStage(int camera_index, const camera::Camera& camera, BallRegionDetectFn detector,
              const BallTrackOptions& track, std::string source_name, BallGuidedFn guided = {});
  ~CameraStage();
  CameraStage(CameraStage&&) noexcept;
  // The candidates of one frame. A damaged encoded frame is counted (stats) and gives a message
  // without candidates; a frame of another size than the camera's throws fv::Error.
  CameraMessage Process(const io::SourceFrame& frame);
  // The fusion's hints for this camera (null: none; not owned, must outlive the stage's use).
  // `no_hint_means_unconfirmed`: a board without a recent position means the cameras together have
  // none (the in-process fusion publishes every position), so unconfirmed_scan_every applies; a
  // camera node cannot tell a fusion node that sends no hints from one without a position until
  // the board says the fusion tells of losses (BallHintBoard::TellsLoss: lost hints).
  void SetHints(BallHintBoard* hints, bool no_hint_means_unconfirmed = true) {
    hints_ = hints;
    no_hint_means_unconfirmed_ = no_hint_means_unconfirmed;
  }
  const CameraStageStats& stats() const { return stats_; }

 private:
  class Track;
  const cv::Mat* Image(const io::SourceFrame& in, const cv::Rect& roi);
  void CheckSize(const cv::Size& got, long long frame) const;
  void SearchBand(const io::SourceFrame& in, std::vector<recon::BallObservation>* candidates);
  // A guided fit at the expected place when no accepted candidate is there: the index in
  // `candidates` of the one it added (after the accepted ones), or -1.
  long AddGuided(const cv::Mat& frame, std::vector<recon::BallObservation>* candidates);
  // Steers the track to where the fusion expects the ball in this frame, if it knows; counts the
  // frames in a row without a recent fused position (unconfirmed_).
  void FollowHint(const io::SourceFrame& in);
  // Whether this frame is searched whole because no fused position confirmed the track lately.
  bool UnconfirmedScan(long long frame);
  // Whether this frame, whose window (where the fusion expects the ball) missed the ball hidden
  // from this camera, leaves the whole frame unsearched (hidden_scan_every); counts such frames.
  [[nodiscard]] bool SkipWholeWhileHidden();
  int camera_index_;
  camera::Camera camera_;
  cv::Size size_;
  BallRegionDetectFn detector_;
  BallGuidedFn guided_;
  BallHintBoard* hints_ = nullptr;
  double last_time_s_ = 0.0;
  int unconfirmed_ = 0;  // frames in a row without a recent fused position (with hints)
  // The ball is hidden from this camera in this frame (hidden_scan_every): the fused state is a
  // fresh line through three positions at least, this camera's window is where it expects the
  // ball, and this camera had no candidate on the ball in the frame of its newest position.
  bool hidden_ = false;
  int hidden_run_ = 0;         // frames in a row whose window missed the ball while it was hidden
  long long last_block_ = -1;  // frame / unconfirmed_scan_every of the last frame processed
  bool no_hint_means_unconfirmed_ = true;
  std::string source_name_;
  std::unique_ptr<Track> track_;
  io::JpegRegionDecoder decoder_;
  cv::Mat decoded_;
  CameraStageStats stats_;
};

}  // namespace fv::pipeline
