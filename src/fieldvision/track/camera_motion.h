// A camera that sways, turns a little or drifts (a phone held by hand, a hovering drone): each
// frame is registered to the first one, the view the camera file's pose holds for, by a
// homography from ORB features matched outside the people's boxes (Rublee et al., ICCV 2011;
// MAGSAC++ homography, Barath et al., CVPR 2020; Hartley & Zisserman ch. 4). A frame is matched to
// the first directly where the two share enough features, else through the previous frame
// (chained). A homography maps a turning camera's whole image exactly and a moving camera's ground
// plane. The players pipeline then works in the first frame's pixels: boxes move there (MapBox),
// and back for TRACKS.csv.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

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
  void Check() const;  // throws fv::Error naming the bad field
};

struct CameraMotionStats {
  int frames = 0;             // frames registered, the first included
  int direct = 0;             // matched to the first frame (the first itself not counted)
  int chained = 0;            // through the last registered frame
  int lost = 0;               // neither: the last registered frame's homography kept
  double max_shift_px = 0.0;  // largest move of the image centre from the first frame's view
  std::string Summary() const;
};

class CameraMotion {
 public:
  explicit CameraMotion(const CameraMotionOptions& options = {});
  // The homography from this frame's pixels to the first frame's (identity for the first), with
  // the people's boxes left out of the matching.
  cv::Matx33d Register(const cv::Mat& bgr, const std::vector<cv::Rect2d>& people);
  const CameraMotionStats& stats() const { return stats_; }

 private:
  struct Features {
    std::vector<cv::KeyPoint> keypoints;  // in frame pixels
    cv::Mat descriptors;
  };
  Features Detect(const cv::Mat& bgr, const std::vector<cv::Rect2d>& people) const;
  // The homography from b's pixels to a's, or false when untrusted.
  bool Match(const Features& a, const Features& b, cv::Matx33d* a_from_b) const;

  CameraMotionOptions options_;
  cv::Ptr<cv::ORB> orb_;
  cv::BFMatcher matcher_{cv::NORM_HAMMING};
  Features first_, previous_;
  cv::Matx33d first_from_previous_ = cv::Matx33d::eye();
  cv::Size size_;
  CameraMotionStats stats_;
};

// A person's box moved by a homography: the bottom centre (the foot) and the top centre map as
// points; the width scales with the height.
cv::Rect2d MapBox(const cv::Matx33d& h, const cv::Rect2d& box);

// Whether a (moved) box is finite and its foot point (bottom centre) lies in a view of `size`.
bool FootInView(const cv::Rect2d& box, const cv::Size& size);

}  // namespace fv::track
