// Bilinear BGR sampling along rays from a ball's centre, shared by the outline fits (ball_fit.h,
// edge_circle.h): the corner pixels of the last cell sampled are kept, as samples a quarter pixel
// apart along a ray mostly share their cell.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace fv::detect {

// The domain of Sampler.
inline bool InsideForSampling(const cv::Mat& img, const Eigen::Vector2d& p) {
  return p.x() >= 0 && p.y() >= 0 && p.x() <= img.cols - 1 && p.y() <= img.rows - 1;
}

// Bilinear BGR samples of an image (points where InsideForSampling holds). The corner pixels of
// the last cell sampled are kept as doubles (samples a quarter pixel apart along a ray mostly
// share their cell).
class Sampler {
 public:
  explicit Sampler(const cv::Mat& img)
      : data_(img.data),
        step_(img.step[0]),
        cols_(img.cols),
        rows_(img.rows),
        x_last0_(img.cols - 2 >= 0 ? img.cols - 2 : 0),
        y_last0_(img.rows - 2 >= 0 ? img.rows - 2 : 0) {}
  // A point inside the image, e.g. one on the segment between two inside points c + t u (the
  // coordinates computed so are monotonic in t).
  void Inside(double x, double y, Eigen::Vector3d* out) {
    const int x0 = std::min(static_cast<int>(x), x_last0_);
    const int y0 = std::min(static_cast<int>(y), y_last0_);
    if (x0 != cell_x0_ || y0 != cell_y0_) Load(x0, y0);
    const double fx = x - cell_x0d_, fy = y - cell_y0d_, gx = 1 - fx, gy = 1 - fy;
    for (int k = 0; k < 3; ++k) {
      (*out)[k] = gy * (gx * a_[k] + fx * b_[k]) + fy * (gx * c_[k] + fx * d_[k]);
    }
  }

 private:
  void Load(int x0, int y0) {
    const int x1 = std::min(x0 + 1, cols_ - 1), y1 = std::min(y0 + 1, rows_ - 1);
    const uint8_t* row0 = data_ + step_ * static_cast<size_t>(y0);
    const uint8_t* row1 = data_ + step_ * static_cast<size_t>(y1);
    const uint8_t* a = row0 + 3 * static_cast<ptrdiff_t>(x0);
    const uint8_t* b = row0 + 3 * static_cast<ptrdiff_t>(x1);
    const uint8_t* c = row1 + 3 * static_cast<ptrdiff_t>(x0);
    const uint8_t* d = row1 + 3 * static_cast<ptrdiff_t>(x1);
    for (int k = 0; k < 3; ++k) {
      a_[k] = a[k];
      b_[k] = b[k];
      c_[k] = c[k];
      d_[k] = d[k];
    }
    cell_x0_ = x0;
    cell_y0_ = y0;
    cell_x0d_ = x0;
    cell_y0d_ = y0;
  }

  const uint8_t* data_;
  size_t step_;
  int cols_, rows_, x_last0_, y_last0_;
  int cell_x0_ = -1, cell_y0_ = -1;
  double cell_x0d_ = -1, cell_y0d_ = -1;
  double a_[3] = {}, b_[3] = {}, c_[3] = {}, d_[3] = {};
};

}  // namespace fv::detect
