#include "fieldvision/calib/board_render.h"

#include <algorithm>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"

namespace fv::calib {

BoardPicture DrawBoard(const BoardSpec& b, double px_per_m) {
  b.Check();
  CheckPositive(px_per_m, "px_per_m");
  BoardPicture out;
  out.px_per_m = px_per_m;
  if (b.type == BoardType::kChessboard) {
    const int sq = static_cast<int>(b.square_m * px_per_m);
    FV_REQUIRE(sq >= 4, "board picture: squares of {} px are too small", sq);
    const int margin = sq;
    out.image = cv::Mat((b.rows + 1) * sq + 2 * margin, (b.cols + 1) * sq + 2 * margin, CV_8U,
                        cv::Scalar(255));
    for (int r = 0; r <= b.rows; ++r) {
      for (int c = 0; c <= b.cols; ++c) {
        if ((r + c) % 2 == 0) {
          out.image(cv::Rect(margin + c * sq, margin + r * sq, sq, sq)).setTo(0);
        }
      }
    }
    // Inner corner (0, 0) is one square in from the board's corner, on the edge between picture
    // pixels (pixel centres at integers).
    out.origin_m = cv::Point2d((margin + sq - 0.5) / px_per_m, (margin + sq - 0.5) / px_per_m);
    return out;
  }
  const auto dict = cv::aruco::getPredefinedDictionary(
      cv::aruco::PREDEFINED_DICTIONARY_NAME(DictionaryId(b.dictionary)));
  const auto board = cv::aruco::CharucoBoard::create(
      b.cols, b.rows, static_cast<float>(b.square_m),
      static_cast<float>(b.marker_m > 0 ? b.marker_m : 0.7 * b.square_m), dict);
  const int margin = static_cast<int>(b.square_m * px_per_m / 2);
  board->draw(cv::Size(static_cast<int>(b.cols * b.square_m * px_per_m) + 2 * margin,
                       static_cast<int>(b.rows * b.square_m * px_per_m) + 2 * margin),
              out.image, margin, 1);
  // OpenCV's ChArUco corners are measured from the board's top-left corner.
  out.origin_m = cv::Point2d((margin - 0.5) / px_per_m, (margin - 0.5) / px_per_m);
  return out;
}

cv::Mat RenderBoardView(const BoardPicture& picture, const camera::Camera& camera,
                        const geometry::Rigid3d& cam_from_board) {
  camera.Check("board view camera");
  const cv::Size size(camera.width, camera.height);
  const Eigen::Matrix3d& r = cam_from_board.rotation;
  const Eigen::Vector3d& t = cam_from_board.translation;
  // Board metres (x, y, 1) -> camera ray: [r1 r2 t]; picture pixel -> board metres: S.
  Eigen::Matrix3d rt;
  rt << r.col(0), r.col(1), t;
  Eigen::Matrix3d s;
  s << 1 / picture.px_per_m, 0, -picture.origin_m.x, 0, 1 / picture.px_per_m, -picture.origin_m.y,
      0, 0, 1;
  const Eigen::Matrix3d ray_from_picture = rt * s;
  cv::Mat out;
  const bool distorted = std::any_of(camera.distortion.begin(), camera.distortion.end(),
                                     [](double d) { return d != 0.0; });
  if (!distorted) {
    Eigen::Matrix3d k;
    k << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1;
    const Eigen::Matrix3d h = k * ray_from_picture;
    cv::Matx33d hm;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) hm(i, j) = h(i, j);
    }
    cv::warpPerspective(picture.image, out, hm, size, cv::INTER_AREA, cv::BORDER_CONSTANT,
                        cv::Scalar(150));
  } else {
    // Every pixel's undistorted ray, mapped onto the picture.
    const Eigen::Matrix3d picture_from_ray = ray_from_picture.inverse();
    cv::Mat map_x(size, CV_32F, cv::Scalar(-1)), map_y(size, CV_32F, cv::Scalar(-1));
    for (int v = 0; v < size.height; ++v) {
      for (int u = 0; u < size.width; ++u) {
        const auto n = camera.Undistort(Eigen::Vector2d(u, v));
        if (!n) continue;
        const Eigen::Vector3d q = picture_from_ray * Eigen::Vector3d(n->x(), n->y(), 1.0);
        if (q.z() <= 0) continue;
        map_x.at<float>(v, u) = static_cast<float>(q.x() / q.z());
        map_y.at<float>(v, u) = static_cast<float>(q.y() / q.z());
      }
    }
    cv::remap(picture.image, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
              cv::Scalar(150));
  }
  cv::GaussianBlur(out, out, cv::Size(3, 3), 0.6);
  return out;
}

}  // namespace fv::calib
