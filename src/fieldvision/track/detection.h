// Person detectors behind one interface, chosen by DetectorOptions::kind:
//  - "nanodet": the pretrained NanoDet-m (RangiLyu 2020, Apache-2.0; COCO "person" class), an ONNX
//    model converted at set-up by scripts/nanodet_to_onnx.py and run with OpenCV's dnn; decoding of
//    its GFL head (Li et al. 2020: per-stride class scores and 4 x 11-bin distance distributions
//    at strides 8/16/32, box = centre -/+ stride * E[bin]);
//  - "hog": OpenCV's HOG + linear SVM people detector (Dalal & Triggs 2005);
//  - "motion": background subtraction for a fixed camera (cv::BackgroundSubtractorMOG2, Zivkovic
//    2004), foreground blobs split and filtered by the expected image size of a person standing at
//    the blob's foot point (from the calibration);
//  - "onnx": a user's YOLO-style ONNX model (rows of cx, cy, w, h, objectness, class scores).
// Every detector applies non-maximum suppression (cv::dnn::NMSBoxes) and keeps only people whose
// foot point is on the ground inside an optional area (the field plus a margin).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/dnn/nanodet.h"

namespace fv::track {

struct Detection {
  cv::Rect2d box;  // image pixels
  double score = 0.0;
};

struct DetectorOptions {
  std::string kind = "nanodet";  // nanodet | hog | motion | onnx
  // Model file (nanodet: default FindModel("nanodet.onnx"); onnx: required).
  std::string model_path;
  // Network input width in pixels (multiple of 32); the height follows the frame's aspect ratio.
  // 0: from the frame (NetInputWidth: half its width, 416..960). 416 is NanoDet's training size;
  // smaller is faster and misses small people.
  int input_width = 0;
  int input_height = 0;          // 0: from the frame's aspect ratio (rounded to a multiple of 32)
  double score_threshold = 0.2;  // lowest score reported (ByteTrack uses the low ones too)
  double nms_iou = 0.5;          // IoU above which the weaker of two boxes is dropped
  // Boxes shorter than this are dropped (far-away people outside the area of interest).
  double min_height_px = 0.0;
  int threads = 0;  // OpenCV threads (cv::setNumThreads); 0 leaves the default
  // HOG: the frame is scaled by this before detection (the window is 64 x 128 pixels, so people
  // smaller than about 100 pixels need upscaling).
  double hog_upscale = 1.6;
  double hog_hit_threshold = 0.0;  // SVM margin
  // The SVM margin that gets score 0.5: score = 1 / (1 + exp(-2 (margin - this))), which puts
  // HOG's margins on the scale of the tracker's score thresholds (measured on PETS S2.L1's first
  // 200 frames: MOTA/IDF1 flat for 1.4..1.8, much worse below 1.1).
  double hog_margin_at_half = 1.5;
  // Motion: MOG2 history and variance threshold; a blob must cover at least this share of the
  // expected person box; person height and width in metres for the expected box.
  int motion_history = 200;
  double motion_var_threshold = 16.0;
  double motion_min_fill = 0.25;
  double person_height_m = 1.75;
  double person_width_m = 0.6;
  // onnx: the class index of "person" in the user's model.
  int onnx_person_class = 0;

  void Check() const;
};

class PersonDetector {
 public:
  virtual ~PersonDetector() = default;
  // Boxes of people in a BGR frame, after NMS, sorted by decreasing score.
  virtual std::vector<Detection> Detect(const cv::Mat& bgr) = 0;
  virtual std::string name() const = 0;
};

// Accepts a detection whose foot point (bottom centre) is in the area of interest.
using FootFilter = std::function<bool(const cv::Point2d& foot_px)>;

// The detector chosen by options.kind. `camera` (calibrated, may be null) gives the motion
// detector the expected person size; `filter` (may be empty) drops detections outside the area.
// Throws fv::Error for bad options or a missing/corrupt model (saying how to get it).
std::unique_ptr<PersonDetector> MakeDetector(const DetectorOptions& options,
                                             const camera::Camera* camera = nullptr,
                                             FootFilter filter = {});

// The filtering every detector applies: drops boxes shorter than options.min_height_px and those
// whose foot point fails `filter` (may be empty), then NMS (options.nms_iou) keeping scores >=
// options.score_threshold, sorted by decreasing score. Idempotent: filtering twice changes nothing.
std::vector<Detection> FilterDetections(std::vector<Detection> detections,
                                        const DetectorOptions& options, const FootFilter& filter);

// Detections of a whole video, MOTChallenge det.txt style: one row per box,
// `frame,-1,bb_left,bb_top,bb_width,bb_height,score` with 1-based frames and no header (MOT's
// det.txt files have 10 columns; the columns after the score are ignored). frames[i] holds the
// boxes of video frame i (0-based).
struct DetectionsFile {
  std::vector<std::vector<Detection>> frames;
};
// The columns of a MOTChallenge file (no header) by position: frame, id, the box, conf, then
// MOT17 ground truth's class and visibility, and a tenth (det.txt's world position is x, y, z
// from the eighth on; unused).
const std::vector<std::string>& MotColumns();
// Writes with full precision (reading gives back the same numbers). Throws fv::Error naming the
// path when it cannot be written.
void WriteDetectionsCsv(const DetectionsFile& detections, const std::string& path);
// Throws fv::Error naming the file and line for a malformed row (fewer than 7 columns, a number
// that does not parse, a frame < 1, a negative box size, a score that is not finite).
DetectionsFile ReadDetectionsCsv(const std::string& path);

// The network input width for a frame `frame_width` pixels wide: `input_width` when > 0, else
// half the frame's width rounded to a multiple of 32 and clamped to 416..960 (768x576 PETS: 416,
// 1280x960: 640, 1920x1080: 960), so people 40-120 px tall in HD frames stay large enough.
int NetInputWidth(int input_width, int frame_width);

// Greedy NMS over boxes sorted by score (cv::dnn::NMSBoxes).
std::vector<Detection> Nms(const std::vector<Detection>& detections, double iou_threshold,
                           double score_threshold = 0.0);
double Iou(const cv::Rect2d& a, const cv::Rect2d& b);

// Where the set-up put the models (dnn/nanodet.h).
using fv::dnn::FindModel;

// NanoDet's decoder for the person class (dnn::DecodeNanoDet), exposed for tests: the six outputs
// (cls8, cls16, cls32: 1 x N x 80; dis8, dis16, dis32: 1 x N x 44) of a net_width x net_height
// input -> person boxes in network pixels with score >= score_threshold (before NMS).
std::vector<Detection> DecodeNanoDet(const std::vector<cv::Mat>& outputs, int net_width,
                                     int net_height, double score_threshold);

}  // namespace fv::track
