// Balls of a few pixels: in a small or blurred ball (and after a JPEG's chroma subsampling) no
// pixel has the ball's colour, every pixel is a mix alpha * ball + (1 - alpha) * background. The
// colour seen at a spot minus the local background, extended from the background by a factor
// t >= 1 (alpha = 1 / t), must land in the ball's colour class; the spot must stand out of a
// uniform background (its difference over the background's spread). Linear mixing model of
// sub-pixel targets (spectral unmixing, Keshava & Mustard 2002) applied to a 3x3 spot against a
// box ring 3..5 px away.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/detect/colour.h"

namespace fv::detect {

struct SmallBallOptions {
  // Looked for only when no other candidate is accepted, and then: "on" anywhere (footage known
  // to show balls of a few pixels); "auto" (default) with a posed camera only where it expects
  // the ball at most max_radius_px (plus the size tolerance) large, without one anywhere; "off"
  // never. Without a posed camera a spot is taken only on the field (BallDetectorOptions::
  // small_field): small spots of the ball's colour are common elsewhere (LEDs on robots, marks on
  // boards). Measured on the real photos (colour detector) against "off": SSL recall 0.811 ->
  // 0.845 at precision 0.940 -> 0.939, MSL unchanged (0.718 / 0.977); without the field check
  // SSL precision 0.926, MSL 0.913. Tracking cameras (`ball`) turn it off
  // (pipeline/ball_job.h).
  std::string mode = "auto";
  // In the detector (ball_detector.h) a spot's unmixed colour is tested against the ball class
  // widened as for region growing (BallDetectorOptions::grow_hue_deg, grow_factor): unmixing
  // extrapolates from a few chroma-subsampled pixels, so its hue and saturation scatter as a
  // blurred ball edge's do. false: the class itself. Measured on the real photos: SSL recall
  // 0.845 -> 0.863 at precision 0.939 -> 0.940 (red-orange and pale far balls), MSL unchanged.
  bool widened_class = true;
  // Background: the ring between boxes of these sides around the spot (pixels, odd).
  int inner_box_px = 7;
  int outer_box_px = 11;
  // Extension factors t tried (alpha = 1 / t): 1 is a pure pixel, 3 a ball covering a third.
  std::vector<double> extensions = {1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0, 4.0};
  // Least contrast: |spot - background| / (background spread + noise_level), both BGR norms.
  double min_contrast = 3.0;
  double noise_level = 10.0;   // added to the background's spread (sensor and JPEG noise)
  double max_radius_px = 4.0;  // larger balls are the blob stages' (and the expected size's)
  int max_spots = 4;           // the strongest spots returned
  // Throws fv::Error naming the bad field.
  void Check() const;
};

struct SmallBall {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();  // contrast-weighted, sub-pixel
  double radius_px = 0.0;  // from the ball's share of the pixels around the spot
  double contrast = 0.0;   // as min_contrast
  double extension = 1.0;  // the smallest t that reached the ball's class
};

// Spots in `roi` of `bgr` (inside `mask` where it is not empty; CV_8U, 255 = searched) whose
// unmixed colour is `table`'s class `bit`, strongest first.
std::vector<SmallBall> FindSmallBalls(const cv::Mat& bgr, const ColourTable& table, uint8_t bit,
                                      const cv::Rect& roi, const cv::Mat& mask,
                                      const SmallBallOptions& options);

}  // namespace fv::detect
