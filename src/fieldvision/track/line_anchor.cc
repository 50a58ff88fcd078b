#include "fieldvision/track/line_anchor.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/camera/opencv_camera.h"
#include "fieldvision/track/camera_motion.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace fv::track {

namespace {

Eigen::Matrix3d ToEigen(const cv::Matx33d& m) {
  Eigen::Matrix3d out;
  cv::cv2eigen(m, out);
  return out;
}

// The rotation nearest to `m` (Frobenius norm) with a positive determinant.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

bool InAnyBox(const Eigen::Vector2d& p, const std::vector<cv::Rect2d>& people) {
  return std::any_of(people.begin(), people.end(), [&p](const cv::Rect2d& b) {
    return p.x() >= b.x - 0.1 * b.width && p.x() <= b.x + 1.1 * b.width && p.y() >= b.y &&
           p.y() <= b.y + 1.1 * b.height;
  });
}

// How a pose fits its line pixels, over those within gate_m of a line: how well they fix it
// both ways on the ground (the smaller over the larger eigenvalue of the scatter of their
// nearest lines' normals, the distance field's gradient) and their median distance in pixels
// from the nearest line's point projected back into the image.
struct LineFit {
  double crossing = 0.0;
  double median_px = std::numeric_limits<double>::infinity();
};

LineFit CheckLineFit(const camera::Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                     const field::FieldModel& field, double gate_m) {
  constexpr double kStepM = 0.02;
  constexpr size_t kMaxPixels = 800;
  const size_t stride = std::max<size_t>(1, pixels.size() / kMaxPixels);
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  std::vector<double> residuals_px;
  for (size_t i = 0; i < pixels.size(); i += stride) {
    const auto ray = camera.RayFromPixel(pixels[i]);
    const auto g = ray ? geometry::IntersectHorizontalPlane(*ray, 0.0) : std::nullopt;
    if (!g) continue;
    const Eigen::Vector2d p = g->head<2>();
    const double d = field.DistanceToLineCentres(p);
    if (d > gate_m) continue;
    const Eigen::Vector2d dx(kStepM, 0), dy(0, kStepM);
    Eigen::Vector2d normal(
        field.DistanceToLineCentres(p + dx) - field.DistanceToLineCentres(p - dx),
        field.DistanceToLineCentres(p + dy) - field.DistanceToLineCentres(p - dy));
    if (!(normal.norm() > 1e-9)) continue;
    normal.normalize();
    scatter += normal * normal.transpose();
    const Eigen::Vector2d on_line = p - d * normal;
    if (const auto uv = camera.Project({on_line.x(), on_line.y(), 0.0})) {
      residuals_px.push_back((*uv - pixels[i]).norm());
    }
  }
  LineFit fit;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
  const double largest = eig.eigenvalues()(1);
  if (largest > 0) fit.crossing = eig.eigenvalues()(0) / largest;
  if (!residuals_px.empty()) fit.median_px = util::Median(residuals_px);
  return fit;
}

// The field's distance table for the options, after checking both (a field without lines has
// none).
calib::LineDistanceMap DistanceMap(const field::FieldModel& field,
                                   const LineAnchorOptions& options) {
  options.Check();
  calib::RequirePaintedLines(field);
  return calib::LineDistanceMap(field, options.refine.lut_resolution_m,
                                options.refine.lut_max_distance_m);
}

}  // namespace

calib::RefineOptions LineAnchorOptions::DefaultRefine() {
  calib::RefineOptions o;
  o.lut_resolution_m = 0.02;
  o.max_move_m = 1.0;
  o.max_iterations = 50;
  o.fix_centre = true;
  return o;
}

void LineAnchorOptions::Check() const {
  refine.Check();
  FV_REQUIRE(min_inliers >= 50, "LineAnchorOptions.min_inliers must be >= 50 (got {})",
             min_inliers);
  CheckInRange(min_crossing, 0, 1, "LineAnchorOptions.min_crossing");
  FV_REQUIRE(work_width_px >= 160, "LineAnchorOptions.work_width_px must be >= 160 (got {})",
             work_width_px);
  CheckPositive(refit_above_px, "LineAnchorOptions.refit_above_px");
  CheckPositive(max_median_px, "LineAnchorOptions.max_median_px");
  CheckPositive(max_correction_share, "LineAnchorOptions.max_correction_share");
}

std::string LineAnchorStats::Summary() const {
  if (tried == 0 && checked == 0) return "field lines: no view to fit";
  return fmt::format(
      "field lines: {} frames between keyframes checked; of {} views to fit (keyframes, frames off "
      "the lines or matched to none) {} held to them (correction median {:.1f} px, largest {:.1f} "
      "px)",
      checked, tried, anchored, corrections_px.empty() ? 0.0 : util::Median(corrections_px),
      corrections_px.empty() ? 0.0
                             : *std::max_element(corrections_px.begin(), corrections_px.end()));
}

LineAnchor::LineAnchor(const camera::Camera& first, const field::FieldModel& field,
                       const LineAnchorOptions& options)
    : first_(first), field_(field), options_(options), map_(DistanceMap(field, options)) {
  first_.Check("moving camera");
  FV_REQUIRE(first_.has_pose, "camera '{}' has no pose: the field lines need one", first_.name);
  k_ = camera::IntrinsicMatrix(first_);
}

camera::Camera LineAnchor::FramePose(const cv::Matx33d& first_from_frame) const {
  if (!options_.refine.fix_centre) return PlanePose(first_from_frame);
  // x_first ~ K R0 Rf^T K^-1 x_frame for a camera turning about its centre.
  const Eigen::Matrix3d a = ToEigen(k_.inv() * NormalizedHomography(first_from_frame) * k_);
  const Eigen::Matrix3d r0 = first_.cam_from_world.rotation;
  const Eigen::Matrix3d rf = NearestRotation(a).transpose() * r0;
  camera::Camera frame = first_;
  frame.cam_from_world.rotation = rf;
  frame.cam_from_world.translation = -rf * first_.CentreInWorld();
  return frame;
}

camera::Camera LineAnchor::PlanePose(const cv::Matx33d& first_from_frame) const {
  // K^-1 H ~ [r1 r2 t] for the frame's homography from the ground (Hartley & Zisserman 8.8.1;
  // Zhang 2000): scaled so that r1 and r2 are unit on average, the sign putting the camera above
  // the ground, the rotation the nearest to [r1 r2 r1 x r2].
  const Eigen::Matrix3d m = ToEigen(k_.inv() * first_from_frame.inv() * PixelsFromGround(first_));
  const double scale = 2.0 / (m.col(0).norm() + m.col(1).norm());
  Eigen::Matrix3d r;
  r.col(0) = scale * m.col(0);
  r.col(1) = scale * m.col(1);
  r.col(2) = r.col(0).cross(r.col(1));
  Eigen::Matrix3d rotation = NearestRotation(r);
  Eigen::Vector3d translation = scale * m.col(2);
  if ((-rotation.transpose() * translation).z() < 0) {
    // The other sign: r1, r2 and t flip, r3 = r1 x r2 stays.
    r.leftCols<2>() *= -1.0;
    rotation = NearestRotation(r);
    translation = -translation;
  }
  camera::Camera frame = first_;
  frame.cam_from_world.rotation = rotation;
  frame.cam_from_world.translation = translation;
  return frame;
}

cv::Matx33d LineAnchor::GroundHomography(const camera::Camera& frame) const {
  return PixelsFromGround(first_) * PixelsFromGround(frame).inv();
}

double LineAnchor::Correction(const camera::Camera& frame, const cv::Matx33d& registered,
                              const cv::Matx33d& held) const {
  // Over a 3x3 grid of the frame, where it sees the ground within kReachM (near the horizon a
  // moved centre's ground homography parts from any other).
  constexpr double kReachM = 60.0;
  double correction = 0.0;
  int measured = 0;
  const Eigen::Matrix3d world_from_pixels =
      frame.cam_from_world.rotation.transpose() * ToEigen(k_.inv());
  const Eigen::Vector3d centre = frame.CentreInWorld();
  for (const double fy : {0.0, 0.5, 1.0}) {
    for (const double fx : {0.0, 0.5, 1.0}) {
      const cv::Point2d p(fx * (first_.width - 1.0), fy * (first_.height - 1.0));
      const Eigen::Vector3d d = world_from_pixels * Eigen::Vector3d(p.x, p.y, 1.0);
      const auto ground = geometry::IntersectHorizontalPlane({centre, d.normalized()}, 0.0);
      if (!ground || (*ground - centre).norm() > kReachM) continue;
      const cv::Point2d a = MapPoint(registered, p), b = MapPoint(held, p);
      correction = std::max(correction, std::hypot(a.x - b.x, a.y - b.y));
      ++measured;
    }
  }
  // No ground in reach: the correction cannot be judged (and is not taken).
  return measured > 0 ? correction : std::numeric_limits<double>::infinity();
}

std::vector<Eigen::Vector2d> LineAnchor::LinePixels(const cv::Mat& bgr,
                                                    const camera::Camera& frame) const {
  const double scale = std::min(1.0, static_cast<double>(options_.work_width_px) / bgr.cols);
  if (scale >= 1.0) return calib::DetectLinePixels(bgr, frame, field_, options_.refine.detect);
  // The frame and its camera scaled (pixel centres kept), the pixels found there scaled back.
  cv::Mat small;
  cv::resize(bgr, small, cv::Size(), scale, scale, cv::INTER_AREA);
  camera::Camera scaled = frame;
  scaled.width = small.cols;
  scaled.height = small.rows;
  scaled.fx *= static_cast<double>(small.cols) / bgr.cols;
  scaled.fy *= static_cast<double>(small.rows) / bgr.rows;
  scaled.cx = (frame.cx + 0.5) * small.cols / bgr.cols - 0.5;
  scaled.cy = (frame.cy + 0.5) * small.rows / bgr.rows - 0.5;
  std::vector<Eigen::Vector2d> pixels =
      calib::DetectLinePixels(small, scaled, field_, options_.refine.detect);
  for (Eigen::Vector2d& p : pixels) {
    p.x() = (p.x() + 0.5) * bgr.cols / small.cols - 0.5;
    p.y() = (p.y() + 0.5) * bgr.rows / small.rows - 0.5;
  }
  return pixels;
}

std::optional<cv::Matx33d> LineAnchor::Correct(const cv::Mat& bgr,
                                               const std::vector<cv::Rect2d>& people,
                                               const cv::Matx33d& first_from_frame, bool keyframe) {
  if (!keyframe && !options_.every_frame) return std::nullopt;
  if (keyframe) ++stats_.tried;
  const camera::Camera start = FramePose(first_from_frame);
  // A degenerate homography (a plane pose from a near-singular one) gives no pose to start from.
  const geometry::Rigid3d& pose = start.cam_from_world;
  if (!pose.rotation.allFinite() || !pose.translation.allFinite() ||
      pose.translation.norm() > 1e6) {
    return std::nullopt;
  }
  std::vector<Eigen::Vector2d> pixels = LinePixels(bgr, start);
  pixels.erase(std::remove_if(pixels.begin(), pixels.end(),
                              [&people](const Eigen::Vector2d& p) { return InAnyBox(p, people); }),
               pixels.end());
  if (static_cast<int>(pixels.size()) < options_.min_inliers) return std::nullopt;
  if (!keyframe) {
    // Another frame is fitted only when its registered view puts its lines off the field's.
    ++stats_.checked;
    if (!(CheckLineFit(start, pixels, field_, options_.refine.gate_m).median_px >
          options_.refit_above_px)) {
      return std::nullopt;
    }
    ++stats_.tried;
  }
  const calib::RefineResult fit =
      calib::RefineWithLinePixels(start, pixels, field_, map_, options_.refine);
  if (!fit.accepted || fit.after.num_inliers < options_.min_inliers) return std::nullopt;
  const LineFit check = CheckLineFit(fit.camera, pixels, field_, options_.refine.gate_m);
  if (check.crossing < options_.min_crossing || check.median_px > options_.max_median_px) {
    return std::nullopt;
  }
  const cv::Matx33d held = GroundHomography(fit.camera);
  const double correction = Correction(start, first_from_frame, held);
  if (!std::isfinite(correction) || correction > options_.max_correction_share * first_.width) {
    return std::nullopt;
  }
  ++stats_.anchored;
  stats_.corrections_px.push_back(correction);
  return held;
}

}  // namespace fv::track
