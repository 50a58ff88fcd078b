// Any ball, not only a coloured one: ball candidates from the pretrained NanoDet's COCO "sports
// ball" class (dnn/nanodet.h; no ball-specific weights), and their combination with the colour
// detector (ball_detector.h) chosen by `--detector colour|dnn|both`. "dnn" runs the network on
// the whole frame (or the search window); "both" confirms colour candidates with the network:
// each is checked in a crop around it (crop_radii of its radius, resized to crop_px, so small
// balls get the network's pixels) and against the whole-frame network balls that hold it. A
// confirmed candidate is accepted (promoted when colour rejected it); an accepted one the network
// does not confirm is kept only with a high colour score or the field around it
// (demote_unconfirmed, the default) or always; a whole-frame network ball that no colour
// candidate lies in completes them; a frame where nothing is accepted is scanned again at every
// pixel (rescan_step_px). Low network scores suffice here because
// colour proposes the places (on the MSL photos a crop score >= 0.1 held 54 of 148 candidates on
// balls and 8 of 2244 elsewhere). Propose with a cheap cue, confirm with a CNN, as in R-CNN
// (Girshick et al., CVPR 2014).
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/dnn/nanodet.h"

namespace fv::detect {

struct DnnBallOptions {
  std::string detector = "colour";  // colour | dnn | both (--detector)
  std::string model_path;           // "" = dnn::FindModel("nanodet.onnx")
  // Whole-frame (or window) search: the network's input width, a multiple of 32; 0 = the frame's
  // width rounded up to a multiple of 32, at least min_input_width (small frames are upscaled:
  // NanoDet's finest stride is 8 px).
  int input_width = 0;
  int min_input_width = 416;
  double score_threshold = 0.25;  // lowest sports-ball score kept as a candidate ("dnn")
  double accept_score = 0.3;      // a network ball is accepted from this score ("dnn")
  // "both": also search the whole frame; its balls confirm colour candidates they hold and, from
  // complete_score, complete them where colour found nothing.
  bool whole_frame = true;
  double complete_score = 0.5;
  double nms_iou = 0.3;
  // "both": colour candidates checked in a square crop of crop_radii x their radius (at least
  // min_crop_px), resized to crop_px; at most max_crops of them, accepted and weak ones first.
  double crop_radii = 4.0;
  int min_crop_px = 24;
  int crop_px = 128;
  int max_crops = 6;
  // Each crop is scored as it is and mirrored left-right, and the two scores averaged (test-time
  // augmentation, as in Krizhevsky et al., NIPS 2012): one pass's score on a few upsampled pixels
  // scatters. Measured on the real photos (`both`): SSL 0.884 / 0.957 -> 0.887 / 0.960, MSL
  // 0.701 / 0.988 -> 0.709 / 0.988, at about 13 % more time per image.
  bool mirror_crops = true;
  // "both": small spots (small_ball.h) are proposed from this contrast instead of the colour
  // detector's SmallBallOptions::min_contrast; those under that are not colour-accepted, so the
  // network judges each one (confirm_score), with demote_unconfirmed off too. Measured on the SSL
  // photos (with mirror_crops; 3 / 2.5 / 2.25 / 2 / 1.75 / 1.5): recall 0.887 / 0.893 / 0.893 /
  // 0.905 / 0.912 / 0.915 at precision 0.960 / 0.961 / 0.958 / 0.955 / 0.955 / 0.952; MSL unchanged
  // (its balls are larger).
  double spot_min_contrast = 2.0;
  // A sports-ball box (crop or whole frame) that holds the candidate's centre and has a half size
  // within [1 / box_size_ratio, box_size_ratio] of its radius confirms it from this score; one
  // the colour detector rejected above the field's edge (BallCandidate::off_field) only from
  // accept_score, as a ball the network finds on its own: there colour says nothing, and lamps
  // and shirts get scores of 0.1-0.3. Measured on the real photos: both SSL 0.826 / 0.951 ->
  // 0.826 / 0.964, both --dnn-keep MSL 0.761 / 0.937 -> 0.778 / 0.968 (complete_score instead:
  // SSL 0.823 / 0.964 in the simulation that chose it).
  double confirm_score = 0.1;
  double box_size_ratio = 2.5;
  // A whole-frame network ball confirms a colour candidate it holds only when the candidate's
  // radius in the network's input is at least this (8: NanoDet's finest stride, the ball two of
  // its cells across). The whole-frame network does not resolve a smaller one: its box there is
  // a robot or a lamp around the spot; the candidate's own (upsampled) crop judges it. Measured
  // on the real photos (`both`, with keep_field_share; 0 / 6 / 8 / 12 px): SSL precision 0.949 /
  // 0.958 / 0.961 / 0.961 at recall 0.912 (the whole-frame boxes had confirmed four far robots
  // and no ball), MSL 0.761 / 0.989 throughout (the balls they confirm are 18-47 px).
  double hold_min_radius_px = 8.0;
  // A colour-accepted candidate the network does not confirm is kept (ranked after the confirmed
  // ones) when its colour score reaches keep_score, else rejected; demote_unconfirmed = false
  // keeps every one. A clear disc of the ball's colour needs no network: the network confirms
  // about half the MSL balls (printed, far). Measured on the real photos (`both`, keep_score
  // 0.6 / 0.5 / 0.45 / 0.4 / 0.3): SSL recall 0.875 / 0.881 / 0.884 / 0.884 / 0.884 at precision
  // 0.960 / 0.957 / 0.957 / 0.951 / 0.942, MSL 0.641 / 0.701 / 0.709 / 0.735 / 0.769 at 0.987 /
  // 0.988 / 0.988 / 0.989 / 0.978; below 0.45 orange LEDs on the SSL robots (colour scores
  // 0.33-0.50) come in.
  double keep_score = 0.45;
  // ... or when at least this share of a ring just around it is field (BallDetector::FieldShare;
  // 0: off): colour alone vouches for a ball on the carpet or grass, as it does for small spots
  // (field_surround.h), whereas orange LEDs on robots, a logo or a shirt are framed by other
  // colours. The MSL balls the network misses are printed, partly hidden by a robot or held in
  // its handler, with colour scores of 0.2-0.4. Measured on the real photos (`both` before
  // hold_min_radius_px; share 0.1 / 0.3 / 0.4 / 0.5 / 0.7 / off): MSL recall 0.769 / 0.769 /
  // 0.761 / 0.735 / 0.718 / 0.709 at precision 0.978 / 0.978 / 0.989 / 0.989 / 0.988 / 0.988,
  // SSL 0.915 / 0.912 / 0.912 / 0.912 / 0.912 / 0.905 at 0.935 / 0.943 / 0.949 / 0.949 / 0.952 /
  // 0.955 (an orange toy and a robot's orange part on the carpet come in).
  double keep_field_share = 0.4;
  bool demote_unconfirmed = true;
  // "both": in a frame where nothing is accepted, the colour stage scans it again at this
  // scanline step (BallDetectorOptions::scan_step_px; 0 or not finer than that step: off). A ball
  // with only a few pixels of its colour (small, blurred, shaded, printed) falls between the fast
  // scan's rows; frames where something was accepted keep their answer. What the rescan adds is
  // accepted as colour candidates are (confirmed by the network or kept by keep_score or
  // keep_field_share); candidates colour rejects are not rescued by a low network score there
  // (the finer scan proposes many more places: on the SSL photos two no-ball frames got a false
  // ball at network scores 0.11-0.14). Measured on the real photos (`bench_photo_robustness`,
  // both; originals, then the mean of the 8 changed copies; before -> after): MSL recall 0.761 ->
  // 0.778 at precision 0.989 -> 0.978, copies 0.703 -> 0.730 at 0.973 -> 0.971; SSL 0.915 ->
  // 0.924 at 0.962 -> 0.959, copies 0.889 -> 0.896 at 0.961 -> 0.959. Step 1 for every frame
  // instead: MSL 0.769 / 0.968, SSL 0.918 / 0.956; with rescues: SSL precision 0.953. It costs
  // the frames it rescans (`eval detect` on the MSL photos: 187 -> 217 ms per image).
  int rescan_step_px = 1;
  // Throws fv::Error naming the bad field.
  void Check() const;
  bool uses_colour() const { return detector != "dnn"; }
  bool uses_dnn() const { return detector != "colour"; }
};

// A network ball as a candidate: centre of the box, radius the mean of its half sides, score the
// network's, accepted from `accept_score`, sigma a tenth of the radius (a box is coarse).
BallCandidate CandidateFromBox(const dnn::DnnBox& box, double accept_score);

// The best score of the network balls `dnn` that confirm each colour candidate (hold its centre,
// half size within box_size_ratio of its radius); 0 where none does, and for candidates under
// hold_min_radius_px in the network's input (`input_scale`: its pixels per frame pixel).
std::vector<double> HoldingScores(const std::vector<BallCandidate>& colour,
                                  const std::vector<BallCandidate>& dnn,
                                  const DnnBallOptions& options, double input_scale);

// Marks the candidates that are not accepted and lie above `boundary` (FieldBoundary::DiscAbove)
// off_field: what "both" confirms only from accept_score.
void MarkOffField(const FieldBoundary& boundary, std::vector<BallCandidate>* candidates);

// The "both" stage, without the network (tested on its own): `colour` (best first) with each
// one's network score `confirm` (crop or whole frame, 0 when not checked; same length), and the
// whole-frame network balls `dnn` (candidates, best first). Returns the candidates best first:
// confirmed ones (accepted, by network score), then colour-accepted unconfirmed ones (with
// demote_unconfirmed those below keep_score whose field_share is below keep_field_share are
// rejected), then completing network balls from complete_score, then the rest. Without `rescue`
// the network confirms only what colour accepted (a colour-rejected candidate stays rejected,
// with its network score).
std::vector<BallCandidate> CombineBallCandidates(const std::vector<BallCandidate>& colour,
                                                 const std::vector<double>& confirm,
                                                 const std::vector<BallCandidate>& dnn,
                                                 const DnnBallOptions& options, bool rescue = true);

// The network part: NanoDet loaded once. Detect and CropScores lock a mutex (one network).
class DnnBallDetector {
 public:
  // Throws fv::Error for bad options or a missing or corrupt model (saying how to get it).
  explicit DnnBallDetector(const DnnBallOptions& options);
  // Network balls in `roi` of `bgr` (the whole frame when empty; nothing outside it is read)
  // from score_threshold ("both": from confirm_score when lower), after NMS, best first, in the
  // frame's pixels.
  std::vector<BallCandidate> Detect(const cv::Mat& bgr, const cv::Rect& roi = cv::Rect()) const;
  // The network's input size for Detect in `roi` of a frame of `frame_size` (the whole frame when
  // empty): input_width (or the roi's width rounded up to a multiple of 32, at least
  // min_input_width) by the roi's aspect; its width over the roi's is Detect's scale.
  cv::Size InputSize(const cv::Size& frame_size, const cv::Rect& roi = cv::Rect()) const;
  // The network's input pixels per frame pixel there (InputSize's width over the roi's).
  double InputScale(const cv::Size& frame_size, const cv::Rect& roi = cv::Rect()) const;
  // The crop score of each candidate (0 for those beyond max_crops, see DnnBallOptions); crops
  // stay inside `roi` (the whole frame when empty).
  std::vector<double> CropScores(const cv::Mat& bgr, const std::vector<BallCandidate>& candidates,
                                 const cv::Rect& roi = cv::Rect()) const;
  const DnnBallOptions& options() const { return options_; }

 private:
  // The best score of the sports-ball boxes in `square` (a crop) that confirm a candidate at
  // centre_px (square pixels) of radius_px; 0 when none does.
  double SquareScore(const cv::Mat& square, const Eigen::Vector2d& centre_px,
                     double radius_px) const;
  DnnBallOptions options_;
  mutable std::mutex mutex_;
  mutable std::unique_ptr<dnn::NanoDet> net_;
};

// The detector chosen by options.detector: the colour detector, the network, or both combined.
// In "dnn" mode the colour detector's radius limits and field mask still filter network balls;
// in "both" its small spots are proposed from DnnBallOptions::spot_min_contrast, and those under
// the colour detector's own contrast are accepted only when the network confirms them (not kept
// by --dnn-keep).
class AnyBallDetector {
 public:
  // Throws fv::Error for bad options, colour or model.
  AnyBallDetector(const BallDetectorOptions& colour, const DnnBallOptions& dnn,
                  const camera::Camera* camera, const field::FieldModel* field);
  // Candidates best first (BallDetector::Detect's contract: `region` empty = whole frame;
  // nothing outside it is read).
  std::vector<BallCandidate> Detect(const cv::Mat& bgr, const cv::Rect& region = cv::Rect()) const;
  // BallDetector::FitAt with the colour detector (a tracked ball's expected place); nullopt
  // without one (--detector dnn).
  std::optional<BallCandidate> FitAt(const cv::Mat& bgr, const cv::Rect& region,
                                     const Eigen::Vector2d& centre_px, double radius_px) const;
  const BallDetector& colour() const { return *colour_; }
  // The colour detector's background (BallDetector::SetBackground).
  void SetBackground(BackgroundFn background) {
    if (fine_colour_ != nullptr) fine_colour_->SetBackground(background);
    colour_->SetBackground(std::move(background));
  }

 private:
  std::vector<BallCandidate> FilterDnn(std::vector<BallCandidate> candidates) const;
  // "both" with one colour detector: its candidates, marked off the field by `boundary`,
  // confirmed by crops and by the whole-frame network balls `whole` (found at `input_scale`),
  // then combined (CombineBallCandidates; `rescue` off for the rescan's extra places).
  std::vector<BallCandidate> ConfirmColour(const cv::Mat& bgr, const cv::Rect& region,
                                           const BallDetector& colour,
                                           const FieldBoundary& boundary,
                                           const std::vector<BallCandidate>& whole,
                                           double input_scale, bool rescue) const;
  // "both": small spots fainter than the colour detector alone takes (its own
  // SmallBallOptions::min_contrast) are not colour-accepted, only worth the network's look.
  void DemoteFaintSpots(std::vector<BallCandidate>* candidates) const;
  // "both": the field share of each colour-accepted candidate that only its field share can
  // keep (not confirmed by `confirm`, below keep_score; DnnBallOptions::keep_field_share).
  void MeasureFieldShares(const cv::Mat& bgr, const cv::Rect& region,
                          const std::vector<double>& confirm,
                          std::vector<BallCandidate>* candidates) const;
  DnnBallOptions dnn_options_;
  double colour_spot_contrast_ = 0.0;
  std::unique_ptr<BallDetector> colour_;
  std::unique_ptr<BallDetector> fine_colour_;  // "both": the rescan (rescan_step_px), or null
  std::unique_ptr<DnnBallDetector> dnn_;
};

}  // namespace fv::detect
