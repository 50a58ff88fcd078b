#include "fieldvision/track/view_canvas.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/camera/opencv_camera.h"
#include "fieldvision/track/camera_motion.h"
#include "fieldvision/util/error.h"

namespace fv::track {

namespace {

cv::Matx33d Shift(double x, double y) { return {1, 0, x, 0, 1, y, 0, 0, 1}; }

}  // namespace

ViewCanvas::ViewCanvas(const camera::Camera& lens, double margin) : lens_(lens) {
  lens_.Check("moving camera's lens");
  FV_REQUIRE(std::isfinite(margin) && margin >= 0 && margin <= 10,
             "the canvas margin must be in [0, 10] image sizes (got {})", margin);
  k_ = camera::IntrinsicMatrix(lens_);
  margin_ = margin;
  const double dx = std::round(margin * lens_.width), dy = std::round(margin * lens_.height);
  canvas_from_first_ = Shift(dx, dy);
  canvas_ = lens_;
  canvas_.name = lens_.name + " canvas";
  canvas_.width = lens_.width + 2 * static_cast<int>(dx);
  canvas_.height = lens_.height + 2 * static_cast<int>(dy);
  // A BGR canvas of at most 100 Mpx (300 MB), as large again for the overlay's lines.
  constexpr double kMaxCanvasPixels = 1e8;
  FV_REQUIRE(static_cast<double>(canvas_.width) * canvas_.height <= kMaxCanvasPixels,
             "a canvas margin of {} makes {}x{} frames a {}x{} canvas (over 100 Mpx): use a "
             "smaller margin",
             margin, lens_.width, lens_.height, canvas_.width, canvas_.height);
  canvas_.cx += dx;
  canvas_.cy += dy;
  canvas_.distortion.clear();
  canvas_.rms_px.reset();
}

ViewCanvas ViewCanvas::Uncalibrated(cv::Size size, double margin) {
  FV_REQUIRE(size.width > 0 && size.height > 0, "the canvas needs the frames' size (got {}x{})",
             size.width, size.height);
  return {camera::Camera::FromFov(size.width, size.height, 60.0), margin};
}

void ViewCanvas::AddFrame(const cv::Matx33d& first_from_frame) {
  const cv::Matx33d h = canvas_from_first_ * first_from_frame;
  FV_REQUIRE(std::isfinite(cv::norm(h)) && cv::determinant(h) != 0,
             "canvas: frame {} has no usable homography", frames() + 1);
  canvas_from_frame_.push_back(NormalizedHomography(h));
  undistorted_from_canvas_.push_back(k_.inv() * canvas_from_frame_.back().inv());
}

const cv::Matx33d& ViewCanvas::CanvasFromFrame(int index) const {
  FV_REQUIRE(index >= 0 && index < frames(), "canvas: frame {} of {}", index, frames());
  return canvas_from_frame_[index];
}

cv::Matx33d ViewCanvas::FirstFromFrame(int index) const {
  return NormalizedHomography(canvas_from_first_.inv() * CanvasFromFrame(index));
}

std::optional<cv::Point2d> ViewCanvas::ToCanvas(int index, const cv::Point2d& frame_px) const {
  const cv::Matx33d& h = CanvasFromFrame(index);
  const auto xn = lens_.Undistort({frame_px.x, frame_px.y});
  if (!xn) return std::nullopt;
  const cv::Vec3d q = h * (k_ * cv::Vec3d(xn->x(), xn->y(), 1.0));
  if (!(q[2] > 0)) return std::nullopt;
  return cv::Point2d(q[0] / q[2], q[1] / q[2]);
}

std::optional<cv::Point2d> ViewCanvas::ToFrame(int index, const cv::Point2d& canvas_px) const {
  FV_REQUIRE(index >= 0 && index < frames(), "canvas: frame {} of {}", index, frames());
  const cv::Vec3d n = undistorted_from_canvas_[index] * cv::Vec3d(canvas_px.x, canvas_px.y, 1.0);
  if (!(n[2] > 0)) return std::nullopt;  // behind the view (K's last row keeps w)
  const Eigen::Vector2d xn(n[0] / n[2], n[1] / n[2]);
  const auto uv = lens_.ProjectFromCamera({xn.x(), xn.y(), 1.0});
  if (!uv) return std::nullopt;
  // Beyond the lens model's fold a far point lands back inside the image: such a point is not
  // in the frame's view.
  const auto back = lens_.Undistort(*uv);
  if (!back || (*back - xn).norm() > 1e-6 * (1.0 + xn.norm())) return std::nullopt;
  return cv::Point2d(uv->x(), uv->y());
}

cv::Rect2d ViewCanvas::BoxToCanvas(int index, const cv::Rect2d& frame_box) const {
  return MapBoxBy([&](const cv::Point2d& p) { return ToCanvas(index, p); }, frame_box);
}

cv::Rect2d ViewCanvas::BoxToFrame(int index, const cv::Rect2d& canvas_box) const {
  return MapBoxBy([&](const cv::Point2d& p) { return ToFrame(index, p); }, canvas_box);
}

cv::Rect ViewCanvas::Footprint(int index) const {
  const int n = 16;
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (int i = 0; i <= n; ++i) {
    const double s = static_cast<double>(i) / n;
    const double w = lens_.width - 1.0, h = lens_.height - 1.0;
    for (const cv::Point2d& p : {cv::Point2d(s * w, 0), cv::Point2d(s * w, h),
                                 cv::Point2d(0, s * h), cv::Point2d(w, s * h)}) {
      if (const auto c = ToCanvas(index, p)) {
        x0 = std::min(x0, c->x), x1 = std::max(x1, c->x);
        y0 = std::min(y0, c->y), y1 = std::max(y1, c->y);
      }
    }
  }
  if (!(x1 >= x0 && y1 >= y0)) return {};
  const cv::Rect box(
      cv::Point(static_cast<int>(std::floor(std::max(x0, -1.0))) - 1,
                static_cast<int>(std::floor(std::max(y0, -1.0))) - 1),
      cv::Point(static_cast<int>(std::ceil(std::min(x1, 1.0 * canvas_.width))) + 2,
                static_cast<int>(std::ceil(std::min(y1, 1.0 * canvas_.height))) + 2));
  return box & cv::Rect(0, 0, canvas_.width, canvas_.height);
}

cv::Rect ViewCanvas::Draw(int index, const cv::Mat& frame, cv::Mat& canvas) {
  FV_REQUIRE(frame.type() == CV_8UC3 && frame.cols == lens_.width && frame.rows == lens_.height,
             "canvas: frame {} is not a {}x{} BGR image", index, lens_.width, lens_.height);
  if (canvas.size() != size() || canvas.type() != CV_8UC3) {
    canvas.create(size(), CV_8UC3);
    canvas.setTo(cv::Scalar::all(0));
    drawn_ = {};
  }
  if (!drawn_.empty()) canvas(drawn_).setTo(cv::Scalar::all(0));
  drawn_ = Footprint(index);
  if (drawn_.empty()) return drawn_;
  // Each region pixel's source: region -> canvas -> undistorted frame pixels -> normalized ->
  // the lens; initUndistortRectifyMap takes the product as its "new camera matrix".
  const cv::Matx33d region_from_normalized =
      Shift(-drawn_.x, -drawn_.y) * CanvasFromFrame(index) * k_;
  cv::Mat map1, map2;
  cv::initUndistortRectifyMap(k_, camera::DistortionRow(lens_), cv::noArray(),
                              region_from_normalized, drawn_.size(), CV_32FC1, map1, map2);
  cv::Mat region = canvas(drawn_);
  cv::remap(frame, region, map1, map2, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  return drawn_;
}

const cv::Mat& ViewCanvas::UndistortedGrid() const {
  if (undistorted_grid_.empty()) {
    cv::Mat mx, my;
    cv::initInverseRectificationMap(k_, camera::DistortionRow(lens_), cv::noArray(), k_,
                                    cv::Size(lens_.width, lens_.height), CV_32FC1, mx, my);
    cv::merge(std::vector<cv::Mat>{mx, my}, undistorted_grid_);
  }
  return undistorted_grid_;
}

cv::Mat ViewCanvas::SeenByFrame(int index, const cv::Mat& canvas_image) const {
  FV_REQUIRE(canvas_image.size() == size(), "canvas: the image is {}x{}, the canvas {}x{}",
             canvas_image.cols, canvas_image.rows, canvas_.width, canvas_.height);
  cv::Mat map;
  cv::perspectiveTransform(UndistortedGrid(), map, cv::Mat(CanvasFromFrame(index)));
  cv::Mat seen;
  cv::remap(canvas_image, seen, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
  return seen;
}

}  // namespace fv::track
