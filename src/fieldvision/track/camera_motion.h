// A camera that sways, turns, pans or drifts (a phone held by hand or following play, a hovering
// drone): each frame is registered to the first one, the view the camera file's pose holds for,
// by a homography (MAGSAC++, Barath et al., CVPR 2020; Hartley & Zisserman ch. 4) from points off
// the people's boxes: corners followed by pyramidal Lucas-Kanade flow from where the camera's last
// step predicts them (Bouguet 2000), else ORB descriptors (Rublee et al., ICCV 2011). A frame is
// matched to the first where its predicted view is back over it, else to the last keyframe (a frame
// that overlapped its own keyframe by less than keyframe_overlap, as in keyframe mosaicking and
// visual odometry: the error adds up per keyframe, not per frame), else to the frame before; a
// fit far from the predicted view gives way to the next. With the camera's lens the homographies
// are between undistorted pixels, where a homography maps a turning camera's whole image exactly
// and a moving camera's ground plane (matched there alone: a feature filter). An anchor may
// correct keyframes and find lost frames (line_anchor.h: the field lines), and the camera's step
// is then also taken from two frames in a row it held. The players pipeline then works on the first
// view widened (view_canvas.h).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include "fieldvision/camera/camera.h"

namespace fv::track {

struct CameraMotionOptions {
  int max_features = 1500;        // ORB keypoints per frame
  int work_width_px = 960;        // frames wider than this are registered at this width
  double ratio_test = 0.75;       // Lowe's ratio between the best and second-best match
  double ransac_px = 3.0;         // RANSAC inlier distance, pixels of the frame
  int min_inliers = 40;           // fewer: the match is not trusted
  double min_inlier_share = 0.3;  // of the ratio-test matches, else not trusted
  // The inliers' convex hull must cover this share of the frame, else the homography is fixed
  // in a strip only (a small overlap) and not trusted.
  double min_inlier_cover = 0.25;
  // A frame registered through the last keyframe or the first frame becomes the next keyframe
  // when it shares less than this share of its area with the keyframe (through the frame before:
  // always).
  double keyframe_overlap = 0.7;
  // A registration that moves a corner of the frame farther than this share of the image width
  // from where the camera's last step predicts it is tried against the next base (a fit on
  // points along one side, wild on the other: 48 px off there in a synthetic pan).
  double max_departure = 0.05;
  // The canvas the frames are tracked on reaches this many image sizes beyond the first view on
  // each side (view_canvas.h): a camera that pans further loses the people beyond.
  double canvas_margin = 1.0;
  void Check() const;  // throws fv::Error naming the bad field
};

struct CameraMotionStats {
  int frames = 0;             // frames registered, the first included
  int direct = 0;             // matched to the first frame (the first itself not counted)
  int keyed = 0;              // through the last keyframe
  int keyframes = 0;          // frames that became keyframes (the first not counted)
  int chained = 0;            // through the last registered frame
  int lost = 0;               // neither: the view predicted from the last known one taken
  int departed = 0;           // registered off the prediction by over max_departure by every base
  bool ground_only = false;   // features matched on the ground alone (SetFeatureFilter)
  int anchored = 0;           // registered frames whose view the anchor corrected (SetAnchor)
  int found_by_anchor = 0;    // frames matched to none, whose predicted view the anchor corrected
  double max_shift_px = 0.0;  // largest move of the image centre from the first frame's view
  std::string Summary() const;
};

class CameraMotion {
 public:
  // With `lens` (intrinsics and distortion; its size is the frames') the homographies are
  // between undistorted pixels of its matrix; without, between pixels.
  explicit CameraMotion(const CameraMotionOptions& options = {},
                        const camera::Camera* lens = nullptr);
  // The homography from this frame's (undistorted) pixels to the first frame's (identity for the
  // first), with the people's boxes left out of the matching.
  cv::Matx33d Register(const cv::Mat& bgr, const std::vector<cv::Rect2d>& people);
  const CameraMotionStats& stats() const { return stats_; }
  // Called with each registered frame (the frame, the people's boxes, its registered homography,
  // whether it is a new keyframe): a homography it gives replaces the registered one
  // (line_anchor.h: held to the field lines), so that the frames registered through it start
  // from it; nullopt keeps the registered. Also with a frame matched to no other, at its
  // predicted view, as a keyframe: a homography it gives is the frame's, else the frame is lost.
  using Anchor = std::function<std::optional<cv::Matx33d>(
      const cv::Mat& bgr, const std::vector<cv::Rect2d>& people, const cv::Matx33d& registered,
      bool keyframe)>;
  void SetAnchor(Anchor anchor) { anchor_ = std::move(anchor); }
  // Features are searched only where the frame's place on the first view (homogeneous, through
  // its predicted view, the sign kept) passes `keep` (tried at the centres of 8 px cells): a
  // camera that moves maps from frame to frame by one homography only over one plane, the ground
  // (OnTheGround in players.cc), not over the stands and boards beside it.
  using FeatureFilter = std::function<bool(const cv::Vec3d& first_px)>;
  void SetFeatureFilter(FeatureFilter keep) {
    keep_ = std::move(keep);
    stats_.ground_only = static_cast<bool>(keep_);
  }

 private:
  struct Features {
    std::vector<cv::Point2f> points;  // ORB's, undistorted pixels (frame pixels without a lens)
    cv::Mat descriptors;
    cv::Mat gray;                                  // the frame at work_width_px
    double scale = 1.0;                            // of gray to the frame
    std::vector<cv::Point2f> corners;              // Shi-Tomasi corners of gray, off the people
    std::vector<cv::Point2f> corners_undistorted;  // the same in undistorted frame pixels
  };
  // A registered frame to match later ones to.
  struct View {
    Features features;
    cv::Matx33d first_from_view = cv::Matx33d::eye();
  };
  // The frame's features off the people's boxes and where the filter keeps them at the frame's
  // `predicted` view.
  Features Detect(const cv::Mat& bgr, const std::vector<cv::Rect2d>& people,
                  const cv::Matx33d& predicted);
  // Whether a frame registered through `base` (nullptr: found by the anchor) at view `h` is the
  // next keyframe (counted in the stats by how it was matched).
  bool NewKeyframe(const View* base, const cv::Matx33d& h, const cv::Matx33d& base_from_this);
  // A frame's view is known (registered, corrected or found by the anchor): the next frames are
  // predicted from it; a step not measured by the registration (`step_known` false) is taken
  // from two views in a row the anchor held.
  void Known(const cv::Matx33d& view, bool by_anchor, bool step_known = false);
  // Clears the cells of a work-scale mask whose centre keep_ refuses at `predicted`.
  void MaskFiltered(const cv::Matx33d& predicted, double scale, cv::Mat* mask);
  // The homography from b's pixels to a's, or false when untrusted.
  bool Match(const Features& a, const Features& b, cv::Matx33d* a_from_b) const;
  // The homography from b's pixels to view a's from a's corners followed into b by pyramidal
  // Lucas-Kanade optical flow, starting where `predicted` (b's first_from_view) puts them, kept
  // where the flow back returns within 0.5 px (Bouguet 2000; Kalal et al., ICPR 2010): for views
  // whose texture repeats (stands, seats) or is sparse (grass, lines), where descriptors fail.
  bool Flow(const View& a, const Features& b, const cv::Matx33d& predicted,
            cv::Matx33d* a_from_b) const;
  // A homography from point pairs with the trust checks (inliers, their share and cover,
  // plausible).
  bool Fit(const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to,
           cv::Matx33d* a_from_b) const;
  // Points at work scale to undistorted frame pixels, and one back.
  std::vector<cv::Point2f> ToUndistorted(std::vector<cv::Point2f> work_px, double scale) const;
  cv::Point2f ToWork(const cv::Point2d& undistorted, double scale) const;
  cv::Point2d Centre() const { return {0.5 * (size_.width - 1), 0.5 * (size_.height - 1)}; }
  // The largest distance between where a and b put this frame's corners (infinite when one
  // puts a corner behind).
  double Departure(const cv::Matx33d& a, const cv::Matx33d& b) const;
  // The share of this frame's area that the view at a_from_b covers.
  double Overlap(const cv::Matx33d& a_from_b) const;

  CameraMotionOptions options_;
  cv::Ptr<cv::ORB> orb_;
  cv::BFMatcher matcher_{cv::NORM_HAMMING};
  std::optional<camera::Camera> lens_;
  View first_, key_, previous_;
  // The last step: a registered frame's view from the frame before, or between two frames the
  // anchor held in a row.
  cv::Matx33d velocity_ = cv::Matx33d::eye();
  int since_registered_ = 0;                    // frames since the last registered one
  cv::Matx33d last_view_ = cv::Matx33d::eye();  // the view of the last frame whose view is known
  int since_known_ = 0;                         // frames lost since then
  bool previous_held_ = false;                  // that view is the anchor's
  cv::Size size_;
  CameraMotionStats stats_;
  Anchor anchor_;
  FeatureFilter keep_;
  std::vector<cv::Point2f> cells_;  // MaskFiltered's cell centres, undistorted (per frame size)
  cv::Size cells_of_;
};

// A homography scaled to unit norm with a positive determinant (a camera's turn or drift keeps
// the image's orientation), not h(2,2) = 1: that is near 0 or negative once the camera has
// turned 90 degrees from the view, where points behind it must stay behind (w < 0).
cv::Matx33d NormalizedHomography(const cv::Matx33d& h);

// A point moved by a homography (no check of w: the caller's points are in front).
cv::Point2d MapPoint(const cv::Matx33d& h, const cv::Point2d& p);
// K [r1 r2 t] of a posed camera: the ground plane (z = 0) to its undistorted pixels, scaled so
// that a ground point's image has the point's depth as its w (positive in front).
cv::Matx33d PixelsFromGround(const camera::Camera& c);

// A person's box moved by a homography: the bottom centre (the foot) and the top centre map as
// points; the width scales with the height.
cv::Rect2d MapBox(const cv::Matx33d& h, const cv::Rect2d& box);
// The same by a point mapping; NaN coordinates where it cannot map the foot or the top.
cv::Rect2d MapBoxBy(const std::function<std::optional<cv::Point2d>(const cv::Point2d&)>& to,
                    const cv::Rect2d& box);

// Whether a (moved) box is finite and its foot point (bottom centre) lies in a view of `size`.
bool FootInView(const cv::Rect2d& box, const cv::Size& size);

}  // namespace fv::track
