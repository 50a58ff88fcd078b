// Synthetic pictures of calibration boards (tests, demos): the flat board drawn at a given
// resolution (chessboard squares or OpenCV's ChArUco drawing) and the board seen by a camera at a
// pose, rendered by mapping every image pixel's ray onto the board plane (a homography for a
// camera without distortion, the camera's own undistortion otherwise), then a light blur.
#pragma once

#include <opencv2/core.hpp>

#include "fieldvision/calib/board.h"
#include "fieldvision/camera/camera.h"

namespace fv::calib {

struct BoardPicture {
  cv::Mat image;             // 8-bit grey, white margin around the board
  double px_per_m = 4000.0;  // picture pixels per board metre
  cv::Point2d origin_m;      // board point (0, 0) of CornerPositions() in picture metres
};

// The flat board (dictionary as in `board` for ChArUco). Throws fv::Error for a bad board.
BoardPicture DrawBoard(const BoardSpec& board, double px_per_m = 4000.0);

// The board seen by `camera` (size, intrinsics, distortion) with the board at cam_from_board
// (board frame: CornerPositions(), z = 0); background grey 150, blur sigma 0.6 px.
cv::Mat RenderBoardView(const BoardPicture& picture, const camera::Camera& camera,
                        const geometry::Rigid3d& cam_from_board);

}  // namespace fv::calib
