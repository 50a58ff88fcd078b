// Tracks drawn on the video a coach looks at: per frame, each person's box in the team's colour
// (else a colour per id), the id or roster name, a short trail of foot points and, with a posed
// camera, the field's lines projected into the image (calib::DrawFieldOverlay), a legend; and a
// video writer for what browsers play: H.264 in MP4 through OpenCV's FFmpeg backend ('avc1'), or
// Motion-JPEG in AVI where that encoder is missing. `players --draw` uses both; other commands
// (ball) can draw their own marks on the same frames before writing.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/track/view_canvas.h"

namespace fv::track {

struct OverlayOptions {
  int trail_frames = 25;    // foot points of this many past frames form the trail (0: none)
  int thickness_px = 2;     // boxes and trails
  bool field_lines = true;  // project the field's lines (needs a posed camera and a field)
  cv::Scalar field_colour = cv::Scalar(255, 255, 255);  // BGR
  bool time_label = true;                               // "frame N, t = S s" in the corner
  // What the colours, dashed boxes, trails and lines mean, in the bottom-left corner (left out
  // where it would cover more than a third of the frame's height or two thirds of its width).
  bool legend = true;
  void Check() const;
};

// BGR colour of a track: team 0 red, team 1 blue, team 2 yellow, team 3 white; no team (-1): a
// fixed palette by id without those colours.
cv::Scalar TrackColour(int id, int team);

class TrackOverlay {
 public:
  // `rows` as in TRACKS.csv (1-based frames); `team_of` and `name_of` by id (may be empty);
  // `camera` (may be null or without pose) and `field` (may be null) for the field lines.
  TrackOverlay(const std::vector<TrackRow>& rows, std::map<int, int> team_of,
               std::map<int, std::string> name_of, const camera::Camera* camera,
               const field::FieldModel* field, const OverlayOptions& options = {});
  // A moving camera (players --moving-camera): the canvas its frames were tracked on
  // (view_canvas.h); the field lines are drawn on the canvas, through its camera, and each frame
  // shows what it sees of them; trails move with the frames. Frames beyond the canvas's get no
  // lines.
  void SetCameraMotion(const ViewCanvas& canvas);
  // Draws TRACKS.csv frame `frame` (1-based) onto `bgr`.
  void Draw(cv::Mat& bgr, int frame) const;

 private:
  struct LegendLine {
    std::vector<cv::Scalar> swatches;
    std::string text;
  };
  std::vector<LegendLine> LegendLines() const;
  // A foot point of frame `from_frame` in the pixels of `to_frame` (1-based; moved with a camera
  // motion); nullopt where it cannot be moved.
  std::optional<cv::Point2d> TrailPoint(const cv::Point2d& foot, int from_frame,
                                        int to_frame) const;
  void DrawLegend(cv::Mat& bgr) const;

  std::map<int, std::vector<TrackRow>> by_frame_;
  std::map<int, int> team_of_;
  std::map<int, std::string> name_of_;
  std::unique_ptr<camera::Camera> camera_;
  std::unique_ptr<field::FieldModel> field_;
  std::optional<ViewCanvas> canvas_;
  cv::Mat canvas_lines_;  // the field lines on the canvas (CV_8U, 255 on a line)
  OverlayOptions o_;
  std::vector<LegendLine> legend_;  // made once
};

struct DrawVideoResult {
  int frames = 0;
  cv::Size frame_size;  // the video's
  std::string path, codec, note;
  std::string Summary() const;
};

// Reads `video` (any file or image pattern fv::io::VideoSource opens) and writes each frame with
// the overlay drawn (one output frame per input frame, at the video's rate; `fps` > 0 overrides;
// images without a rate play at the stand-in and the note says so), up to `max_frames` (0: all).
DrawVideoResult DrawTracksVideo(const std::string& video, const std::string& out,
                                const TrackOverlay& overlay, double fps = 0, int max_frames = 0);

}  // namespace fv::track
