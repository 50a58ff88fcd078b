// The background of a static camera: the per-pixel median of frames sampled across its video (a
// moving ball is in few of them) and the frame-to-background noise (the median of the samples'
// per-channel differences from it). A ball hardly set apart from its surroundings by
// colour (a shaded ball before grey stands, an olive ball against the sun) still differs from
// what lies behind it: a disc that differs from the background where a ring around it does not
// is a thing of that size that came into view. A still ball, a moving or refocusing camera and a
// change of light give no such evidence (the disc is background, or the ring changed too), so it
// can only add to the colour checks, never remove a ball. The frames are kept reduced by `scale`
// (area averaging), and a frame's disc and ring are reduced alike before the comparison. Method:
// median background subtraction (Cucchiara et al., "Detecting moving objects, ghosts, and shadows
// in video streams", PAMI 2003).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace fv::detect {

struct BackgroundOptions {
  // Frames sampled evenly across the video (3..99): a thing is background where it stays in more
  // than half of them. Each costs a decoded frame (the 4-camera kick render: 7 add 0.2 s of CPU
  // to 1.9 s; 5, 7 and 9 find the same balls in the low-sun renders).
  int samples = 7;
  // Frames kept reduced by this factor (1 or 2): a quarter of the memory and of the median's work
  // at 2; a ball of 4 px radius is then a disc of 2.
  int scale = 2;
  // A pixel differs from the background when one of its channels differs by at least
  // min_difference (0..255) and noise_factor times the frame-to-background noise.
  double min_difference = 12.0;
  double noise_factor = 6.0;
  // A camera whose sampled frames differ from their median by more than max_noise (the median of
  // their per-channel differences) or on more than max_changed_share of their values moves or
  // changes exposure: no usable background. A static camera's noise is its sensor's and its
  // codec's, halved by the reduction (the renders: 1-3; a camera panning over stands: 6).
  double max_noise = 5.0;
  double max_changed_share = 0.2;
  // A disc apart from the background: at least min_disc_share of the disc (0.8 of the radius)
  // differs from it and at most max_ring_share of a ring (1.5..2.2 radii) does. A ball's shadow
  // beside it, and JPEG ringing around its edge, change up to a third of the ring (the low-sun
  // renders: 0.00-0.36 around balls at least 70 % visible, their discs 0.99-1.00); a thing in
  // front of a moving robot, or a change of light, changes most of it.
  double min_disc_share = 0.7;
  double max_ring_share = 0.4;
  // ChangedDisc: a changed part this round (area / enclosing circle's area; a disc 1, a square
  // 0.64) is taken as a disc.
  double min_round_fill = 0.6;
  void Check() const;  // throws fv::Error naming the bad field
};

// What a disc's pixels say against the background.
struct BackgroundEvidence {
  double disc_share = 0.0;  // share of the disc's pixels that differ
  double ring_share = 1.0;  // share of the ring's pixels that differ
  bool apart = false;       // both shares as BackgroundOptions asks (enough pixels read)
  bool measured = false;    // the shares were read (a usable background, enough pixels)
};

class Background {
 public:
  // From at least 3 BGR frames of one size, each reduced by options.scale (Reduce) from frames
  // of `full_size`; throws fv::Error otherwise.
  // The frames' pixels are sorted in place (moved in: a copied cv::Mat would share them).
  Background(std::vector<cv::Mat>&& reduced_frames, const cv::Size& full_size,
             const BackgroundOptions& options);
  // A frame as the background keeps it: reduced by `scale` (area averaging; odd edges dropped).
  static cv::Mat Reduce(const cv::Mat& bgr, int scale);
  // Whether the sampled frames agree enough for a background (a static camera, steady light).
  bool usable() const { return usable_; }
  // Frame-to-background noise (the median of the samples' per-channel differences) and the
  // difference a changed pixel shows in a channel at least.
  double noise() const { return noise_; }
  double threshold() const { return threshold_; }
  // Share of the sampled frames' values (pixels and channels) that differ from the background.
  double changed_share() const { return changed_share_; }
  const cv::Mat& image() const { return image_; }  // reduced by options.scale
  int scale() const { return options_.scale; }
  // The disc (centre_px, 0.8 radius_px) and ring (1.5..2.2 radius_px) of `bgr` (the background's
  // size) against the background, reading only pixels inside `roi` (empty: the frame). Not apart
  // when the background is not usable, the frame is not of its size or too few pixels were read.
  BackgroundEvidence Compare(const cv::Mat& bgr, const Eigen::Vector2d& centre_px, double radius_px,
                             const cv::Rect& roi = cv::Rect()) const;
  // The largest part of `box` (full-resolution pixels, clipped to roi) that differs from the
  // background, as a circle (full-resolution centre and the radius of its area) when it is round
  // enough (its area at least min_round_fill of its enclosing circle's) to be a ball; nullopt
  // otherwise or when the background is not usable.
  struct Circle {
    Eigen::Vector2d centre_px;
    double radius_px;
  };
  std::optional<Circle> ChangedDisc(const cv::Mat& bgr, const cv::Rect& box,
                                    const cv::Rect& roi = cv::Rect()) const;
  std::string Summary() const;

 private:
  // `box` (full-resolution) in reduced pixels wholly inside roi and the image; empty if none.
  cv::Rect ReducedInside(const cv::Rect& box, const cv::Rect& roi) const;
  // The part of full-resolution `bgr` that reduces to `reduced` (reduced pixels), reduced.
  cv::Mat ReducedPart(const cv::Mat& bgr, const cv::Rect& reduced) const;
  bool Changed(const cv::Vec3b& a, const cv::Vec3b& b) const;
  BackgroundOptions options_;
  cv::Size full_size_;
  cv::Mat image_;  // CV_8UC3, reduced by options_.scale
  double noise_ = 0.0;
  double threshold_ = 0.0;
  double changed_share_ = 0.0;
  bool usable_ = false;
};

}  // namespace fv::detect
