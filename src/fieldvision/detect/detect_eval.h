// Checking the ball detector on a user's labelled frames (`fieldvision eval detect`): images (a
// folder, searched recursively, a glob or a pattern) or a video, with boxes as YOLO txt files
// (one per image, `class cx cy w h` normalised; an image without a file has no ball) or a CSV
// (`image|frame,x,y,w,h` in pixels, or the circles of `synth`'s truth_2d.csv, one camera's rows,
// balls less visible than `min_visible` not judged). Per image the best accepted candidate counts
// as a hit when its centre lies inside a labelled box grown by `grow` (25 % by default, each side);
// recall over images with a ball, precision over images with a detection (the score of the shared
// RoboCup photo sets, shared/data/robocup-ball-photos/README).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/dnn_ball.h"

namespace fv::detect {

struct LabelledImage {
  std::string image;              // file path, or the video plus frame for a video
  int frame = -1;                 // frame index in a video; -1 for image files
  std::vector<cv::Rect2d> boxes;  // ball boxes in pixels (the chosen class only)
  bool has_label_file = false;    // YOLO: false when no label file was found (no ball)
  std::string label_file;         // YOLO: the label file read ("" for a CSV or none)
  bool judged = true;  // false: its only ball is less visible than the labels' min_visible
};

// Where the labels are and which of them count.
struct LabelOptions {
  std::string labels;  // YOLO folder or CSV; "" = YOLO files beside the images
  int class_id = 0;    // YOLO class of the ball
  // truth_2d.csv (frame,cam,u_px,v_px,radius_px,visible_fraction): the camera whose rows are the
  // video's labels; "" = the video's file name without extension, else its folder's name.
  std::string camera;
  // truth_2d.csv: a frame whose ball is less visible than this is not judged (the issue's
  // measure: every ball with at least 70 % of its outline visible).
  double min_visible = 0.7;
};

// Reads the labels of `images` from `labels` (a folder of YOLO txt files or a CSV). YOLO files
// are looked up as LABELS/<path relative to image_root with .txt> and then LABELS/<stem>.txt.
// Throws fv::Error naming file and line for a row that does not parse.
std::vector<LabelledImage> ReadYoloLabels(const std::vector<std::string>& images,
                                          const std::string& image_root, const std::string& labels,
                                          int class_id);
// The frames of `video` (a folder searched recursively, a glob, an image pattern, or a video
// file with a CSV) with their ball boxes from `labels.labels` (a YOLO folder, "" for YOLO files
// beside the images, a CSV `image|frame,x,y,w,h`, or truth_2d.csv's circles); a video's items
// have their frame index. Throws fv::Error starting with `what` for no images, labels that are
// neither, no label file, or a truth_2d.csv without the video's camera.
std::vector<LabelledImage> ListLabelledImages(const std::string& video, const LabelOptions& labels,
                                              const std::string& what);
// One YOLO txt file: boxes of class `class_id` in pixels for an image of width x height.
std::vector<cv::Rect2d> ReadYoloFile(const std::string& path, int class_id, int width, int height);

struct DetectEvalOptions {
  std::string video;  // folder (recursive), glob, image pattern or video file
  LabelOptions labels;
  std::string camera;          // optional camera file (size checks); frames must then match it
  std::string field;           // optional field (name or JSON): the field mask, with a posed camera
  double grow = 0.25;          // box growth for a hit (each side, share of the box size)
  int list_misses = 30;        // misses and false detections listed in the summary
  std::string out;             // optional CSV, one row per image
  std::string candidates_out;  // optional CSV, one row per candidate with its measurements
  // Optional new (or empty) folder: each miss and false detection drawn (eval_drawing.h).
  std::string draw_misses;
  bool progress = true;
  // Called once the labels are read and the outputs checked, before the first image ("": none).
  std::function<void()> on_start;
  // Optional change made to each image before it is searched (bench/photo_robustness_bench.cc:
  // the photos re-encoded, scaled, darker, another white balance); its boxes are scaled by the
  // changed image's size over the original's. Neither with a camera (its frames have a fixed
  // size) nor with draw_misses.
  std::function<cv::Mat(const cv::Mat&)> transform;
  BallDetectorOptions detector;
  DnnBallOptions dnn;  // --detector colour|dnn|both (dnn_ball.h)
  // A video from a posed (static) camera: low-contrast candidates are compared with its
  // background (camera_background.h).
  bool background = true;
  // Throws fv::Error naming the bad field.
  void Check() const;
};

struct DetectEvalImage {
  std::string image;
  int boxes = 0;
  bool detected = false;  // an accepted candidate
  bool hit = false;
  double u = 0, v = 0, radius_px = 0, score = 0;
  double centre_err_px = -1;       // hit: distance to the box centre
  double centre_err_rel = -1;      // ... divided by the box's half size
  bool candidate_on_ball = false;  // any candidate (accepted or not) inside a grown box
  bool accepted_on_ball = false;   // an accepted one there (a miss: another ranked first)
  // The ball's size: half the longer side of its box (the hit one, else the largest); 0 without.
  double ball_radius_px = 0;
  std::string reason;  // for a miss: the best rejected candidate on the ball's reason
};

// Recall per ball size (DetectEvalImage::ball_radius_px) in the bins < 3, 3-6, 6-12, 12-24 and
// >= 24 px: "< 3 px 0.620 (31/50), 3-6 px ...", the empty bins left out ("" without balls).
std::string RecallBySize(const std::vector<DetectEvalImage>& images);

struct DetectEvalResult {
  std::vector<DetectEvalImage> images;
  int with_ball = 0;
  int detected = 0;  // images with an accepted candidate
  int hits = 0;
  int false_detections = 0;
  int no_label_file = 0;
  int not_judged = 0;  // frames whose ball is less visible than LabelOptions::min_visible
  int drawn = 0;       // images drawn into DetectEvalOptions::draw_misses
  std::string drawn_dir;
  std::string background;   // CameraBackground::Summary, "" when none was set up
  std::string camera_note;  // the camera fitted to the video (camera/frame_size.h), or ""
  double seconds = 0.0;
  double recall() const { return with_ball > 0 ? double(hits) / with_ball : 0.0; }
  double precision() const { return detected > 0 ? double(hits) / detected : 0.0; }
  // Recall (also per ball size), precision, centre errors and the first `list` misses and false
  // detections.
  std::string Summary(int list = 30) const;
};

// Scores one image's candidates against its boxes (best accepted candidate first).
DetectEvalImage ScoreImage(const std::vector<BallCandidate>& candidates,
                           const std::vector<cv::Rect2d>& boxes, double grow);

DetectEvalResult EvaluateDetector(const DetectEvalOptions& options);

}  // namespace fv::detect
