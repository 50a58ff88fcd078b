// Learning a colour class from pixels a user points at (`fieldvision color learn`): positive
// pixels (small neighbourhoods of clicked points, or the inscribed ellipse of a box around the
// ball) give an HSV box from trimmed percentiles (hue as the shortest circular interval), widened
// for shading; negative pixels (clicked, or by default the frame away from the positives) then
// shrink the box greedily where that removes most negatives per positive lost. One frame, or
// several pooled (boxes across a video's frames, a folder of labelled images: the light and the
// camera's white balance vary). The result is a colour file (class + field green + line white),
// a purity report (the share of ball and of background pixels in the class) and an overlay image
// of what the class selects.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/detect/colour.h"

namespace fv::detect {

struct ColourLearnOptions {
  std::vector<Eigen::Vector2d> points;           // positive pixels (u, v)
  std::optional<cv::Rect> roi;                   // or a box around the ball
  std::vector<Eigen::Vector2d> negative_points;  // pixels that are not the class
  int point_radius_px = 2;                       // neighbourhood of each point
  double trim = 0.02;           // share of positives trimmed at each end of each channel
  double hue_margin_deg = 6.0;  // widening of the learned box
  double saturation_margin = 25.0;
  double value_margin = 40.0;
  double min_recall = 0.9;  // shrinking stops before fewer positives than this remain
  // A class that still selects more than this share of the negative (background) pixels is
  // reported as bad (ColourLearnResult::bad); `color learn` then does not write it.
  double max_background_share = 0.02;
  std::string class_name = "ball";
  // Throws fv::Error naming the bad field; `need_pixels`: points or roi must be given (one frame).
  void Check(bool need_pixels = true) const;
};

// One frame of several to learn from: the ball's pixels (points, or boxes around balls) and,
// optionally, pixels that are not the class.
struct ColourLearnSample {
  cv::Mat bgr;
  std::vector<Eigen::Vector2d> points;
  std::vector<cv::Rect> boxes;
  std::vector<Eigen::Vector2d> negative_points;
};

struct ColourLearnResult {
  ColourSpec spec;  // the learned class (first, the ball class) + field + line
  ColourRange range;
  int positives = 0;
  int negatives = 0;
  double recall = 0.0;         // share of positives inside the learned range
  double negative_rate = 0.0;  // share of negatives inside it
  bool bad = false;            // negative_rate > max_background_share: not a usable class
  cv::Mat overlay;             // the frame, darkened where the class is absent
  std::string Summary() const;
};

// Learns from one BGR frame. Throws fv::Error for points or a region outside the frame, or too
// few positives.
ColourLearnResult LearnColour(const cv::Mat& bgr, const ColourLearnOptions& options);
// Learns from several frames, their pixels pooled; each frame gives at most its share of
// kMaxLearnNegatives background pixels (evenly spaced), so that every frame weighs alike. The
// options' points, roi and negative points are not used; the overlay is the first frame's.
// Throws fv::Error (naming the frame's index) for no frames, a frame that is not BGR or has no
// ball pixels, pixels outside a frame, or too few positives in all.
inline constexpr size_t kMaxLearnNegatives = 500000;
ColourLearnResult LearnColour(const std::vector<ColourLearnSample>& samples,
                              const ColourLearnOptions& options);

// The stages of LearnColour, in order; each callable alone.
struct ColourLearnMasks {
  cv::Mat positive;  // CV_8U, 255 at the class's pixels
  cv::Mat negative;  // CV_8U, 255 around the negative points
  cv::Mat near;      // CV_8U, 255 near the positives: kept out of the default negatives
};
// Draws the points and the region into masks; throws fv::Error for any outside the frame.
ColourLearnMasks MarkLearnPixels(const cv::Mat& bgr, const ColourLearnOptions& options);
// The same for a sample's points and boxes.
ColourLearnMasks MarkLearnPixels(const ColourLearnSample& sample, int point_radius_px);
// Clears the `positive` pixels inside `roi` that are closer to the median colour of the ring
// around it than to the colour at its centre (a loose box also holds background).
void DropBackgroundLikePixels(const cv::Mat& bgr, const cv::Rect& roi, cv::Mat& positive);
struct ColourLearnPixels {
  std::vector<cv::Vec3b> positive;  // HSV_FULL (hue 0..255 for 0..360 degrees)
  std::vector<cv::Vec3b> negative;  // clicked, or every third pixel away from the positives
};
ColourLearnPixels GatherLearnPixels(const cv::Mat& hsv_full, const ColourLearnMasks& masks);
// The shortest circular interval of 8-bit hues holding all but the share `trim` at each end:
// {first hue, length}, the first hue the lowest of equally short ones.
std::pair<int, int> ShortestHueInterval(const std::vector<cv::Vec3b>& hsv_full, double trim);
// The hue interval and the trimmed low saturation and value, widened by the margins.
ColourRange InitialColourRange(const std::vector<cv::Vec3b>& positive,
                               const ColourLearnOptions& options);
// Greedy shrinking: one bound a step at a time where it removes most negatives per positive
// lost, while the recall stays at least `min_recall`.
ColourRange ShrinkAgainstNegatives(ColourRange range, const ColourLearnPixels& pixels,
                                   double min_recall);
// Share of the HSV_FULL pixels inside `range` (as the colour table sees it); 0 for none.
double ColourRangeShare(const ColourRange& range, const std::vector<cv::Vec3b>& hsv_full);
// The class, then field green and line white unless the class is one of them.
ColourSpec LearnedColourSpec(const ColourRange& range, const std::string& class_name);
// The frame dimmed except where the class is, the positives outlined.
cv::Mat LearnOverlay(const cv::Mat& bgr, const ColourSpec& spec, const cv::Mat& positive);

// Reads frame `frame` of `video` (file or image pattern); throws naming the video when it cannot
// be opened or is shorter.
cv::Mat ReadVideoFrame(const std::string& video, int frame);
// Frames `frames` (any order, repeats allowed) of `video`, read in one pass; the same errors.
std::vector<cv::Mat> ReadVideoFrames(const std::string& video, const std::vector<int>& frames);

// "u,v;u,v;..." -> points; "x,y,w,h" -> rectangle. Throw naming `what` on bad syntax.
std::vector<Eigen::Vector2d> ParsePoints(const std::string& text, const std::string& what);
cv::Rect ParseRect(const std::string& text, const std::string& what);

}  // namespace fv::detect
