// The canvas a moving camera's frames are tracked on: the first frame's view as a pinhole camera
// without lens distortion (posed as the camera file says), widened by a margin on each side, so
// that people a camera turns or drifts to beyond its first view still have pixels and field
// positions. A frame's pixel reaches the canvas through the lens (undistorted) and the frame's
// homography to the first view in undistorted pixels (CameraMotion), and goes back by the inverse
// and the lens (Hartley & Zisserman ch. 4 and 7.4). Images move between the two with
// cv::initUndistortRectifyMap / cv::initInverseRectificationMap and cv::remap.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"

namespace fv::track {

class ViewCanvas {
 public:
  // `lens`: the camera the frames come from (its size, intrinsics, distortion and, if any, the
  // pose of the first frame). `margin`: how many image widths (heights) the canvas reaches beyond
  // the first view on each side (>= 0).
  ViewCanvas(const camera::Camera& lens, double margin);
  // Without a camera file: frames of `size`, no distortion, no pose.
  static ViewCanvas Uncalibrated(cv::Size size, double margin);

  // The canvas as a camera: pinhole, the lens's focal lengths, posed as the lens.
  const camera::Camera& camera() const { return canvas_; }
  const camera::Camera& lens() const { return lens_; }
  cv::Size size() const { return {canvas_.width, canvas_.height}; }

  // The next frame's homography from its undistorted pixels to the first frame's
  // (CameraMotion::Register with this lens).
  void AddFrame(const cv::Matx33d& first_from_frame);
  int frames() const { return static_cast<int>(canvas_from_frame_.size()); }
  // From the undistorted pixels of frame `index` (0-based) to the canvas, and to the first view.
  const cv::Matx33d& CanvasFromFrame(int index) const;
  cv::Matx33d FirstFromFrame(int index) const;
  double margin() const { return margin_; }

  // A pixel of frame `index` on the canvas; nullopt where the lens cannot undistort it.
  std::optional<cv::Point2d> ToCanvas(int index, const cv::Point2d& frame_px) const;
  // A canvas pixel in frame `index`'s pixels; nullopt where it lies behind that view.
  std::optional<cv::Point2d> ToFrame(int index, const cv::Point2d& canvas_px) const;
  // A person's box moved between the two (foot and top centre as points, MapBox); a box that
  // cannot be moved comes back with NaN coordinates.
  cv::Rect2d BoxToCanvas(int index, const cv::Rect2d& frame_box) const;
  cv::Rect2d BoxToFrame(int index, const cv::Rect2d& canvas_box) const;

  // Frame `index` drawn onto `canvas` (canvas-sized, CV_8UC3; allocated if empty) where it lands;
  // the part it covered for the previous call is cleared first, so only this frame's pixels are
  // there. Returns the canvas region drawn.
  cv::Rect Draw(int index, const cv::Mat& frame, cv::Mat& canvas);
  // What frame `index` sees of a canvas-sized image (the overlay's field lines): frame-sized.
  cv::Mat SeenByFrame(int index, const cv::Mat& canvas_image) const;

 private:
  // The canvas region a frame covers (its border mapped), clipped to the canvas.
  cv::Rect Footprint(int index) const;
  // Each frame pixel's undistorted pixel (x, y), computed once on first use.
  const cv::Mat& UndistortedGrid() const;

  camera::Camera lens_;
  camera::Camera canvas_;
  double margin_ = 0;
  cv::Matx33d k_;                  // the lens's intrinsics (the undistorted pixels' matrix)
  cv::Matx33d canvas_from_first_;  // the margin's shift
  std::vector<cv::Matx33d> canvas_from_frame_;
  std::vector<cv::Matx33d> undistorted_from_canvas_;  // K^-1 (canvas_from_frame)^-1, per frame
  cv::Rect drawn_;                                    // the region Draw filled last
  mutable cv::Mat undistorted_grid_;                  // CV_32FC2, frame-sized
};

}  // namespace fv::track
