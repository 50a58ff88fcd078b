#include "fieldvision/track/camera_motion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "fieldvision/camera/opencv_camera.h"
#include "fieldvision/util/error.h"

namespace fv::track {

void CameraMotionOptions::Check() const {
  FV_REQUIRE(max_features >= 50, "CameraMotionOptions.max_features must be >= 50 (got {})",
             max_features);
  FV_REQUIRE(work_width_px >= 160, "CameraMotionOptions.work_width_px must be >= 160 (got {})",
             work_width_px);
  FV_REQUIRE(std::isfinite(ratio_test) && ratio_test > 0 && ratio_test <= 1,
             "CameraMotionOptions.ratio_test must be in (0, 1] (got {})", ratio_test);
  CheckPositive(ransac_px, "CameraMotionOptions.ransac_px");
  FV_REQUIRE(min_inliers >= 8, "CameraMotionOptions.min_inliers must be >= 8 (got {})",
             min_inliers);
  CheckInRange(min_inlier_cover, 0, 1, "CameraMotionOptions.min_inlier_cover");
  CheckInRange(min_inlier_share, 0, 1, "CameraMotionOptions.min_inlier_share");
  CheckInRange(keyframe_overlap, 0, 1, "CameraMotionOptions.keyframe_overlap");
  CheckPositive(max_departure, "CameraMotionOptions.max_departure");
  CheckInRange(canvas_margin, 0, 10, "CameraMotionOptions.canvas_margin");
}

std::string CameraMotionStats::Summary() const {
  return fmt::format(
      "camera motion{}: of {} frames after the first, {} matched to it directly, {} through a "
      "keyframe ({} keyframes), {} through the frame before, {} not at all (the camera's "
      "motion carried on){}{}{}; the image centre moved up to {:.0f} px",
      ground_only ? " (features on the ground alone)" : "", std::max(0, frames - 1), direct, keyed,
      keyframes, chained, lost,
      anchored > 0 ? fmt::format(", {} held to the field lines", anchored) : "",
      found_by_anchor > 0 ? fmt::format(", {} found by the field lines alone", found_by_anchor)
                          : "",
      departed > 0
          ? fmt::format(", {} registered far from the predicted view by every base", departed)
          : "",
      max_shift_px);
}

namespace {

// `points` mapped by h, or nullopt when one of them goes behind (w <= 0) or to infinity.
std::optional<std::vector<cv::Point2f>> MapInFront(const cv::Matx33d& h,
                                                   const std::vector<cv::Point2d>& points) {
  std::vector<cv::Point2f> mapped;
  for (const cv::Point2d& p : points) {
    const cv::Vec3d q = h * cv::Vec3d(p.x, p.y, 1.0);
    if (!(q[2] > 1e-9) || !std::isfinite(q[0]) || !std::isfinite(q[1])) return std::nullopt;
    mapped.emplace_back(static_cast<float>(q[0] / q[2]), static_cast<float>(q[1] / q[2]));
  }
  return mapped;
}

// A homography a camera's turn or drift can give: finite, the frame's corners stay in front
// (no horizon inside the frame) and its area changes by less than 4x.
bool Plausible(const cv::Matx33d& h, const cv::Size& size) {
  const auto mapped = MapInFront(h, {{0, 0},
                                     {size.width - 1.0, 0},
                                     {size.width - 1.0, size.height - 1.0},
                                     {0, size.height - 1.0}});
  if (!mapped) return false;
  const double ratio = std::abs(cv::contourArea(*mapped)) / (static_cast<double>(size.area()));
  return ratio > 0.25 && ratio < 4.0;
}

}  // namespace

cv::Matx33d NormalizedHomography(const cv::Matx33d& h) {
  const double n = cv::norm(h);
  if (!(n > 0) || !std::isfinite(n)) return h;
  return h * ((cv::determinant(h) < 0 ? -1.0 : 1.0) / n);
}

cv::Point2d MapPoint(const cv::Matx33d& h, const cv::Point2d& p) {
  const cv::Vec3d q = h * cv::Vec3d(p.x, p.y, 1.0);
  return {q[0] / q[2], q[1] / q[2]};
}

cv::Matx33d PixelsFromGround(const camera::Camera& c) {
  const Eigen::Matrix3d& r = c.cam_from_world.rotation;
  const Eigen::Vector3d& t = c.cam_from_world.translation;
  const cv::Matx33d rt(r(0, 0), r(0, 1), t.x(), r(1, 0), r(1, 1), t.y(), r(2, 0), r(2, 1), t.z());
  return camera::IntrinsicMatrix(c) * rt;
}

cv::Rect2d MapBox(const cv::Matx33d& h, const cv::Rect2d& box) {
  return MapBoxBy([&h](const cv::Point2d& p) { return std::optional(MapPoint(h, p)); }, box);
}

cv::Rect2d MapBoxBy(const std::function<std::optional<cv::Point2d>(const cv::Point2d&)>& to,
                    const cv::Rect2d& box) {
  const double cx = box.x + 0.5 * box.width;
  const std::optional<cv::Point2d> mapped_foot = to({cx, box.y + box.height});
  const std::optional<cv::Point2d> mapped_top = to({cx, box.y});
  if (!mapped_foot || !mapped_top) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan, nan};
  }
  const cv::Point2d foot = *mapped_foot, top = *mapped_top;
  const double height = std::hypot(foot.x - top.x, foot.y - top.y);
  const double width = box.height > 0 ? box.width * height / box.height : box.width;
  return {foot.x - 0.5 * width, foot.y - height, width, height};
}

bool FootInView(const cv::Rect2d& box, const cv::Size& size) {
  const double u = box.x + 0.5 * box.width, v = box.y + box.height;
  return std::isfinite(box.area()) && u >= 0 && v >= 0 && u < size.width && v < size.height;
}

CameraMotion::CameraMotion(const CameraMotionOptions& options, const camera::Camera* lens)
    : options_(options) {
  options_.Check();
  if (lens != nullptr) {
    lens->Check("moving camera's lens");
    lens_ = *lens;
  }
  orb_ = cv::ORB::create(options_.max_features);
}

CameraMotion::Features CameraMotion::Detect(const cv::Mat& bgr,
                                            const std::vector<cv::Rect2d>& people,
                                            const cv::Matx33d& predicted) {
  const double scale = std::min(1.0, static_cast<double>(options_.work_width_px) / bgr.cols);
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  if (scale < 1.0) cv::resize(gray, gray, cv::Size(), scale, scale, cv::INTER_AREA);
  cv::Mat mask(gray.size(), CV_8U, cv::Scalar(255));
  // Each person's box widened, and lengthened below the feet for the shadow: a group of people
  // moving together would otherwise outvote sparse background (grass) in the fit.
  for (const cv::Rect2d& b : people) {
    const double x0 = b.x - 0.25 * b.width, x1 = b.x + 1.25 * b.width;
    const double y0 = b.y - 0.1 * b.height, y1 = b.y + 1.4 * b.height;
    const cv::Rect r(cv::Point(static_cast<int>(std::floor(x0 * scale)) - 2,
                               static_cast<int>(std::floor(y0 * scale)) - 2),
                     cv::Point(static_cast<int>(std::ceil(x1 * scale)) + 2,
                               static_cast<int>(std::ceil(y1 * scale)) + 2));
    const cv::Rect clipped = r & cv::Rect(0, 0, mask.cols, mask.rows);
    if (!clipped.empty()) mask(clipped).setTo(0);
  }
  MaskFiltered(predicted, scale, &mask);
  Features f;
  f.gray = gray;
  f.scale = scale;
  cv::goodFeaturesToTrack(gray, f.corners, options_.max_features / 3, 0.01, 8, mask);
  f.corners_undistorted = ToUndistorted(f.corners, scale);
  std::vector<cv::KeyPoint> keypoints;
  orb_->detectAndCompute(gray, mask, keypoints, f.descriptors);
  if (keypoints.empty()) return f;
  // ORB's corners from its coarser pyramid levels are pixels off: each is moved to the corner's
  // sub-pixel place in the image registered (at work_width_px).
  cv::KeyPoint::convert(keypoints, f.points);
  cv::cornerSubPix(gray, f.points, cv::Size(3, 3), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 10, 0.03));
  f.points = ToUndistorted(f.points, scale);
  return f;
}

void CameraMotion::MaskFiltered(const cv::Matx33d& predicted, double scale, cv::Mat* mask) {
  if (!keep_) return;
  // The filter at the centres of kCellPx cells (of the image registered): corners are then chosen
  // among the kept ones (goodFeaturesToTrack's quality is relative to the strongest corner in the
  // mask). The centres are undistorted once for the frames' size.
  constexpr int kCellPx = 8;
  if (cells_of_ != mask->size()) {
    std::vector<cv::Point2f> centres;
    for (int y = 0; y < mask->rows; y += kCellPx) {
      for (int x = 0; x < mask->cols; x += kCellPx) {
        centres.emplace_back(std::min(x + 0.5f * kCellPx, mask->cols - 1.0f),
                             std::min(y + 0.5f * kCellPx, mask->rows - 1.0f));
      }
    }
    cells_ = ToUndistorted(centres, scale);
    cells_of_ = mask->size();
  }
  size_t i = 0;
  for (int y = 0; y < mask->rows; y += kCellPx) {
    for (int x = 0; x < mask->cols; x += kCellPx, ++i) {
      const cv::Point2f& p = cells_[i];
      if (keep_(predicted * cv::Vec3d(p.x, p.y, 1.0))) continue;
      (*mask)(cv::Rect(x, y, kCellPx, kCellPx) & cv::Rect(0, 0, mask->cols, mask->rows)).setTo(0);
    }
  }
}

bool CameraMotion::NewKeyframe(const View* base, const cv::Matx33d& h,
                               const cv::Matx33d& base_from_this) {
  if (base == nullptr) {
    ++stats_.found_by_anchor;
    return true;
  }
  if (base == &first_) {
    ++stats_.direct;
    return Overlap(key_.first_from_view.inv() * h) < options_.keyframe_overlap;
  }
  if (base == &key_) {
    ++stats_.keyed;
    return Overlap(base_from_this) < options_.keyframe_overlap;
  }
  ++stats_.chained;  // the keyframe is out of reach: this frame is the next one
  return true;
}

void CameraMotion::Known(const cv::Matx33d& view, bool by_anchor, bool step_known) {
  // Two views the anchor held in a row measure the step (its corrections are not drift there).
  if (!step_known && by_anchor && previous_held_) {
    velocity_ = NormalizedHomography(last_view_.inv() * view);
  }
  last_view_ = view;
  since_known_ = 0;
  previous_held_ = by_anchor;
}

std::vector<cv::Point2f> CameraMotion::ToUndistorted(std::vector<cv::Point2f> work_px,
                                                     double scale) const {
  for (cv::Point2f& p : work_px) p *= 1.0 / scale;
  if (lens_ && !work_px.empty()) {
    const cv::Matx33d k = camera::IntrinsicMatrix(*lens_);
    // Iterated to convergence, as Camera::Undistort (OpenCV's default stops after 5 steps).
    cv::undistortPoints(
        std::vector<cv::Point2f>(work_px), work_px, k, camera::DistortionRow(*lens_), cv::noArray(),
        k, cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-9));
  }
  return work_px;
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
    from.push_back(b.points[m[0].queryIdx]);
    to.push_back(a.points[m[0].trainIdx]);
  }
  return Fit(from, to, a_from_b);
}

cv::Point2f CameraMotion::ToWork(const cv::Point2d& undistorted, double scale) const {
  cv::Point2d px = undistorted;
  if (lens_) {
    const auto uv = lens_->ProjectFromCamera(
        {(undistorted.x - lens_->cx) / lens_->fx, (undistorted.y - lens_->cy) / lens_->fy, 1.0});
    if (!uv) return {-1e6f, -1e6f};
    px = {uv->x(), uv->y()};
  }
  return {static_cast<float>(px.x * scale), static_cast<float>(px.y * scale)};
}

bool CameraMotion::Flow(const View& a, const Features& b, const cv::Matx33d& predicted,
                        cv::Matx33d* a_from_b) const {
  const Features& fa = a.features;
  if (static_cast<int>(fa.corners.size()) < options_.min_inliers || b.gray.empty()) return false;
  // Each corner's place in b as the prediction has it: LK corrects from there.
  const cv::Matx33d b_from_a = predicted.inv() * a.first_from_view;
  const std::vector<cv::Point2f>& undistorted = fa.corners_undistorted;
  std::vector<cv::Point2f> ahead;
  ahead.reserve(undistorted.size());
  for (const cv::Point2f& p : undistorted) {
    const cv::Vec3d q = b_from_a * cv::Vec3d(p.x, p.y, 1.0);
    ahead.push_back(q[2] > 1e-9 ? ToWork({q[0] / q[2], q[1] / q[2]}, b.scale)
                                : cv::Point2f(-1e6f, -1e6f));
  }
  const cv::Size window(21, 21);
  const int levels = 3;
  const cv::TermCriteria stop(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30, 0.01);
  std::vector<cv::Point2f> back = fa.corners;
  std::vector<uchar> found, found_back;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(fa.gray, b.gray, fa.corners, ahead, found, error, window, levels, stop,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  cv::calcOpticalFlowPyrLK(b.gray, fa.gray, ahead, back, found_back, error, window, levels, stop,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<cv::Point2f> from, to;
  for (size_t i = 0; i < fa.corners.size(); ++i) {
    const cv::Point2f d = back[i] - fa.corners[i];
    if (found[i] && found_back[i] && d.dot(d) < 0.25f) {
      from.push_back(ahead[i]);
      to.push_back(undistorted[i]);
    }
  }
  return Fit(ToUndistorted(from, b.scale), to, a_from_b);
}

bool CameraMotion::Fit(const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to,
                       cv::Matx33d* a_from_b) const {
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

double CameraMotion::Departure(const cv::Matx33d& a, const cv::Matx33d& b) const {
  const double w = size_.width - 1.0, h = size_.height - 1.0;
  const std::vector<cv::Point2d> corners = {{0, 0}, {w, 0}, {w, h}, {0, h}};
  const auto in_a = MapInFront(a, corners), in_b = MapInFront(b, corners);
  if (!in_a || !in_b) return std::numeric_limits<double>::infinity();
  double worst = 0.0;
  for (size_t i = 0; i < corners.size(); ++i) {
    worst = std::max(worst, static_cast<double>(cv::norm((*in_a)[i] - (*in_b)[i])));
  }
  return worst;
}

double CameraMotion::Overlap(const cv::Matx33d& a_from_b) const {
  const double w = size_.width, h = size_.height;
  const auto mapped = MapInFront(a_from_b, {{0, 0}, {w, 0}, {w, h}, {0, h}});
  if (!mapped) return 0.0;
  const std::vector<cv::Point2f> frame = {{0, 0},
                                          {static_cast<float>(w), 0},
                                          {static_cast<float>(w), static_cast<float>(h)},
                                          {0, static_cast<float>(h)}};
  std::vector<cv::Point2f> common;
  const float area = cv::intersectConvexConvex(*mapped, frame, common, true);
  return std::max(0.0f, area) / (w * h);
}

cv::Matx33d CameraMotion::Register(const cv::Mat& bgr, const std::vector<cv::Rect2d>& people) {
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "camera motion: the frame must be 8-bit BGR");
  if (lens_) {
    FV_REQUIRE(bgr.cols == lens_->width && bgr.rows == lens_->height,
               "camera motion: frame {} is {}x{}, the camera {}x{}", stats_.frames + 1, bgr.cols,
               bgr.rows, lens_->width, lens_->height);
  }
  ++stats_.frames;
  if (stats_.frames == 1) {
    size_ = bgr.size();
    first_ = {Detect(bgr, people, cv::Matx33d::eye()), cv::Matx33d::eye()};
    key_ = first_;
    previous_ = first_;
    velocity_ = cv::Matx33d::eye();
    Known(cv::Matx33d::eye(), false, true);
    return first_.first_from_view;
  }
  FV_REQUIRE(bgr.size() == size_, "camera motion: frame {} is {}x{}, the first was {}x{}",
             stats_.frames, bgr.cols, bgr.rows, size_.width, size_.height);
  // This frame's view as the camera's last step predicts it from the last frame whose view is
  // known (registered or found by the anchor; constant motion, carried over frames lost, for at
  // most kMaxCarried of them).
  constexpr int kMaxCarried = 10;
  cv::Matx33d predicted = last_view_;
  for (int i = 0; i <= std::min(since_known_, kMaxCarried - 1); ++i) {
    predicted = predicted * velocity_;
  }
  predicted = NormalizedHomography(predicted);
  Features f = Detect(bgr, people, predicted);
  // Optical flow from the prediction first (the first frame where the view is back over it, the
  // keyframe, the frame before), then descriptors (a jump, or a view found again after frames
  // lost): descriptors on repeated texture can lock on a copy of it one period off.
  struct Attempt {
    const View* view;
    bool flow;  // else descriptors
  };
  const Attempt attempts[] = {{&first_, true},  {&key_, true},  {&previous_, true},
                              {&first_, false}, {&key_, false}, {&previous_, false}};
  // A registration that puts the frame's corners farther from the prediction than
  // max_departure (a fit whose inliers lie on one side, extrapolated) gives way to the next
  // attempt; when all do, the one nearest the prediction is taken.
  cv::Matx33d a_from_this;
  const View* base = nullptr;
  double nearest = std::numeric_limits<double>::infinity();
  const double limit = options_.max_departure * size_.width;
  for (const Attempt& a : attempts) {
    if (a.flow && a.view == &first_ && Overlap(predicted) <= 0.5) continue;
    cv::Matx33d fitted;
    if (a.flow ? Flow(*a.view, f, predicted, &fitted) : Match(a.view->features, f, &fitted)) {
      const double departure = Departure(a.view->first_from_view * fitted, predicted);
      if (base == nullptr || departure < nearest) {  // infinite: a corner behind either view
        nearest = departure;
        a_from_this = fitted;
        base = a.view;
      }
      if (departure <= limit) break;
    }
  }
  if (base != nullptr && nearest > limit) ++stats_.departed;
  // Neither: the anchor may still hold the predicted view (the field lines), and it becomes the
  // next keyframe; else the predicted view is taken, and the last registered frame stays the one
  // to chain from (a blank or blurred frame must not become the base of the next).
  std::optional<cv::Matx33d> held;
  if (base == nullptr && anchor_) held = anchor_(bgr, people, predicted, true);
  if (base == nullptr && (!held || static_cast<int>(f.corners.size()) < options_.min_inliers)) {
    // A frame without texture to match later ones to keeps the frame before as the base.
    ++since_registered_;
    if (!held) {
      ++stats_.lost;
      ++since_known_;
      previous_held_ = false;
      return predicted;
    }
    ++stats_.found_by_anchor;
    Known(NormalizedHomography(*held), true);
    return last_view_;
  }
  cv::Matx33d h = held ? *held : base->first_from_view * a_from_this;
  const bool new_key = NewKeyframe(held ? nullptr : base, h, a_from_this);
  h = NormalizedHomography(h);
  // The step from the last registered frame (over frames lost, the step before is kept; a frame
  // found by the anchor alone measures it only from a frame the anchor held too: from a
  // registered one its correction is drift).
  if (!held && since_registered_ == 0) {
    velocity_ = NormalizedHomography(previous_.first_from_view.inv() * h);
  }
  since_registered_ = 0;
  bool by_anchor = held.has_value();
  if (anchor_ && !held) {
    if (const std::optional<cv::Matx33d> corrected = anchor_(bgr, people, h, new_key)) {
      h = NormalizedHomography(*corrected);
      ++stats_.anchored;
      by_anchor = true;
    }
  }
  Known(h, by_anchor, /*step_known=*/!held);
  const cv::Point2d centre = Centre();
  const cv::Point2d moved = MapPoint(h, centre);
  stats_.max_shift_px =
      std::max(stats_.max_shift_px, std::hypot(moved.x - centre.x, moved.y - centre.y));
  // Corners were chosen where the filter keeps them at the predicted view: at a view found or
  // corrected far from it, chosen again there (this frame may be the base of the next).
  if (keep_ && !(Departure(h, predicted) <= 0.01 * size_.width)) f = Detect(bgr, people, h);
  previous_ = {std::move(f), h};
  if (new_key) {
    key_ = previous_;
    ++stats_.keyframes;
  }
  return h;
}

}  // namespace fv::track
