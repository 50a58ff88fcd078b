// What `eval detect --draw-misses DIR` shows of each miss and false detection: the frame (small
// ones enlarged, pixels kept square), the labelled ball's box and the area a hit's centre must
// lie in, every candidate as `detect --draw` draws them, close-ups of the ball and of a false
// detection, what went wrong on a band above and a legend below; one JPEG per image in a new (or
// empty) folder outside the images' folder.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/detect_eval.h"
#include "fieldvision/util/output_path.h"

namespace fv::detect {

// A close-up beside the frame: the square of 3x the larger side of `around` (at least 24 px)
// enlarged to about 240 px, drawn only where that enlarges more than the frame's own view.
struct EvalZoom {
  cv::Rect2d around;
  std::string caption;
};

// The drawing of one judged image: `title` lines on the band above (wrapped to the width), the
// frame, the close-ups in a column beside it, a legend below.
cv::Mat DrawEvalImage(const cv::Mat& bgr, const std::vector<cv::Rect2d>& boxes, double grow,
                      const std::vector<BallCandidate>& candidates,
                      const std::vector<std::string>& title,
                      const std::vector<EvalZoom>& zooms = {});

// The enlargement DrawEvalImage gives an image of this size: the smallest whole factor that
// makes its shorter side at least 480 px (at most 8, and the longer side at most 8000 px; 1 for
// larger images).
int EvalDrawingScale(int width, int height);

// Writes the misses and false detections of an `eval detect` run into `dir`.
class MissDrawings {
 public:
  // Throws fv::Error (naming --draw-misses and the folder) when `dir` holds files, is not a
  // folder, cannot be made, or lies in `video` (a folder, searched recursively) or in the folder
  // of one of `image_files` (a later run over them would score the drawings).
  MissDrawings(const std::string& dir, const std::string& video,
               const std::vector<std::string>& image_files);
  // The folder is util::NewFolder's: removed again when the run fails before drawing into it.
  // Draws image number `index` when it is a miss or a false detection; returns whether it did.
  bool Add(int index, const LabelledImage& item, const DetectEvalImage& scored,
           const std::vector<BallCandidate>& candidates, const cv::Mat& bgr, double grow);
  void Keep() { folder_->Keep(); }  // the run succeeded: the folder stays, drawings or not
  int written() const { return written_; }
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
  int written_ = 0;
  std::optional<util::NewFolder> folder_;
};

}  // namespace fv::detect
