#include "fieldvision/track/camera_motion.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"

namespace fv::track {

void CameraMotionOptions::Check() const {
  FV_REQUIRE(max_features >= 50, "CameraMotionOptions.max_features must be >= 50 (got {})",
             max_features);
  FV_REQUIRE(work_width_px >= 160, "CameraMotionOptions.work_width_px must be >= 160 (got {})",
             work_width_px);
  FV_REQUIRE(std::isfinite(ratio_test) && ratio_test > 0 && ratio_test <= 1,
             "CameraMotionOptions.ratio_test must be in (0, 1] (got {})", ratio_test);
  FV_REQUIRE(std::isfinite(ransac_px) && ransac_px > 0,
             "CameraMotionOptions.ransac_px must be > 0 (got {})", ransac_px);
  FV_REQUIRE(min_inliers >= 8, "CameraMotionOptions.min_inliers must be >= 8 (got {})",
             min_inliers);
  FV_REQUIRE(std::isfinite(min_inlier_cover) && min_inlier_cover >= 0 && min_inlier_cover <= 1,
             "CameraMotionOptions.min_inlier_cover must be in [0, 1] (got {})", min_inlier_cover);
  FV_REQUIRE(std::isfinite(min_inlier_share) && min_inlier_share >= 0 && min_inlier_share <= 1,
             "CameraMotionOptions.min_inlier_share must be in [0, 1] (got {})", min_inlier_share);
}

std::string CameraMotionStats::Summary() const {
  return fmt::format(
      "camera motion: of {} frames after the first, {} matched to it directly, {} through the "
      "last frame matched, {} not at all (the last view kept); the image centre moved up to "
      "{:.0f} px",
      std::max(0, frames - 1), direct, chained, lost, max_shift_px);
}

namespace {

cv::Point2d Apply(const cv::Matx33d& h, const cv::Point2d& p) {
  const cv::Vec3d q = h * cv::Vec3d(p.x, p.y, 1.0);
  return {q[0] / q[2], q[1] / q[2]};
}

// A homography a camera's turn or drift can give: finite, the frame's corners stay in front
// (no horizon inside the frame) and its area changes by less than 4x.
bool Plausible(const cv::Matx33d& h, const cv::Size& size) {
  const std::vector<cv::Point2d> corners = {
      {0, 0}, {size.width - 1.0, 0}, {size.width - 1.0, size.height - 1.0}, {0, size.height - 1.0}};
  std::vector<cv::Point2f> mapped;
  for (const cv::Point2d& p : corners) {
    const cv::Vec3d q = h * cv::Vec3d(p.x, p.y, 1.0);
    if (!(q[2] > 1e-9) || !std::isfinite(q[0]) || !std::isfinite(q[1])) return false;
    mapped.emplace_back(static_cast<float>(q[0] / q[2]), static_cast<float>(q[1] / q[2]));
  }
  const double ratio = std::abs(cv::contourArea(mapped)) / (static_cast<double>(size.area()));
  return ratio > 0.25 && ratio < 4.0;
}

}  // namespace

cv::Rect2d MapBox(const cv::Matx33d& h, const cv::Rect2d& box) {
  const double cx = box.x + 0.5 * box.width;
  const cv::Point2d foot = Apply(h, {cx, box.y + box.height});
  const cv::Point2d top = Apply(h, {cx, box.y});
  const double height = std::hypot(foot.x - top.x, foot.y - top.y);
  const double width = box.height > 0 ? box.width * height / box.height : box.width;
  return {foot.x - 0.5 * width, foot.y - height, width, height};
}

bool FootInView(const cv::Rect2d& box, const cv::Size& size) {
  const double u = box.x + 0.5 * box.width, v = box.y + box.height;
  return std::isfinite(box.area()) && u >= 0 && v >= 0 && u < size.width && v < size.height;
}

CameraMotion::CameraMotion(const CameraMotionOptions& options) : options_(options) {
  options_.Check();
  orb_ = cv::ORB::create(options_.max_features);
}

CameraMotion::Features CameraMotion::Detect(const cv::Mat& bgr,
                                            const std::vector<cv::Rect2d>& people) const {
  const double scale = std::min(1.0, static_cast<double>(options_.work_width_px) / bgr.cols);
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  if (scale < 1.0) cv::resize(gray, gray, cv::Size(), scale, scale, cv::INTER_AREA);
  cv::Mat mask(gray.size(), CV_8U, cv::Scalar(255));
  for (const cv::Rect2d& b : people) {
    const cv::Rect r(cv::Point(static_cast<int>(std::floor(b.x * scale)) - 2,
                               static_cast<int>(std::floor(b.y * scale)) - 2),
                     cv::Point(static_cast<int>(std::ceil((b.x + b.width) * scale)) + 2,
                               static_cast<int>(std::ceil((b.y + b.height) * scale)) + 2));
    const cv::Rect clipped = r & cv::Rect(0, 0, mask.cols, mask.rows);
    if (!clipped.empty()) mask(clipped).setTo(0);
  }
  Features f;
  orb_->detectAndCompute(gray, mask, f.keypoints, f.descriptors);
  // ORB's corners from its coarser pyramid levels are pixels off: each is moved to the corner's
  // sub-pixel place in the image registered (at work_width_px).
  if (!f.keypoints.empty()) {
    std::vector<cv::Point2f> corners;
    cv::KeyPoint::convert(f.keypoints, corners);
    cv::cornerSubPix(gray, corners, cv::Size(3, 3), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 10, 0.03));
    for (size_t i = 0; i < corners.size(); ++i) f.keypoints[i].pt = corners[i];
  }
  for (cv::KeyPoint& k : f.keypoints) k.pt *= 1.0 / scale;
  return f;
}

bool CameraMotion::Match(const Features& a, const Features& b, cv::Matx33d* a_from_b) const {
  if (a.descriptors.rows < options_.min_inliers || b.descriptors.rows < options_.min_inliers) {
    return false;
  }
  std::vector<std::vector<cv::DMatch>> knn;
  matcher_.knnMatch(b.descriptors, a.descriptors, knn, 2);
  std::vector<cv::Point2f> from, to;
  for (const auto& m : knn) {
    if (m.size() < 2 || m[0].distance >= options_.ratio_test * m[1].distance) continue;
    from.push_back(b.keypoints[m[0].queryIdx].pt);
    to.push_back(a.keypoints[m[0].trainIdx].pt);
  }
  if (static_cast<int>(from.size()) < options_.min_inliers) return false;
  std::vector<uchar> inlier;
  const cv::Mat h = cv::findHomography(from, to, cv::USAC_MAGSAC, options_.ransac_px, inlier);
  if (h.empty()) return false;
  const int n = cv::countNonZero(inlier);
  if (n < options_.min_inliers || n < options_.min_inlier_share * from.size()) return false;
  // Inliers in a narrow strip (a small overlap) fix the homography there only.
  std::vector<cv::Point2f> kept, hull;
  for (size_t i = 0; i < from.size(); ++i) {
    if (inlier[i]) kept.push_back(from[i]);
  }
  cv::convexHull(kept, hull);
  if (cv::contourArea(hull) < options_.min_inlier_cover * size_.area()) return false;
  *a_from_b = cv::Matx33d(h);
  return Plausible(*a_from_b, size_);
}

cv::Matx33d CameraMotion::Register(const cv::Mat& bgr, const std::vector<cv::Rect2d>& people) {
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "camera motion: the frame must be 8-bit BGR");
  Features f = Detect(bgr, people);
  ++stats_.frames;
  if (stats_.frames == 1) {
    size_ = bgr.size();
    first_ = f;
    previous_ = std::move(f);
    first_from_previous_ = cv::Matx33d::eye();
    return first_from_previous_;
  }
  FV_REQUIRE(bgr.size() == size_, "camera motion: frame {} is {}x{}, the first was {}x{}",
             stats_.frames, bgr.cols, bgr.rows, size_.width, size_.height);
  cv::Matx33d h;
  cv::Matx33d previous_from_this;
  if (Match(first_, f, &h)) {
    ++stats_.direct;
  } else if (Match(previous_, f, &previous_from_this)) {
    h = first_from_previous_ * previous_from_this;
    ++stats_.chained;
  } else {
    // Neither: the last view is kept, and the last registered frame stays the one to chain from
    // (a blank or blurred frame must not become the base of the next).
    ++stats_.lost;
    return first_from_previous_;
  }
  h *= 1.0 / h(2, 2);
  const cv::Point2d centre(0.5 * (size_.width - 1), 0.5 * (size_.height - 1));
  const cv::Point2d moved = Apply(h, centre);
  stats_.max_shift_px =
      std::max(stats_.max_shift_px, std::hypot(moved.x - centre.x, moved.y - centre.y));
  previous_ = std::move(f);
  first_from_previous_ = h;
  return h;
}

}  // namespace fv::track
