// Test images drawn by hand for the detect tests: a field-like background and balls rendered by
// supersampling (exact coverage), optionally ray-cast through a pinhole camera so that the true
// centre is the projection of the sphere centre. Used only by *_test.cc and the benchmark.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/codecs/codecs.h"
#include "fieldvision/util/random.h"

namespace fv::detect::test_util {

inline const cv::Vec3b kGrass(50, 140, 60);
inline const cv::Vec3b kOrange(0, 110, 255);

// `m` filled with Gaussian noise from `rng` (cv::randn draws from OpenCV's global RNG, whose
// state depends on what ran before in the process: a test's images would then not follow its
// seed).
inline void FillNormal(cv::Mat& m, util::Rng& rng, double mean, double sigma) {
  cv::RNG cv_rng(rng.engine()());
  cv_rng.fill(m, cv::RNG::NORMAL, cv::Scalar::all(mean), cv::Scalar::all(sigma));
}

// `img` with Gaussian noise of `sigma` added (saturating).
inline cv::Mat WithNoise(const cv::Mat& img, util::Rng& rng, double sigma) {
  cv::Mat noise(img.size(), CV_16SC3), tmp, out;
  FillNormal(noise, rng, 0, sigma);
  img.convertTo(tmp, CV_16SC3);
  tmp += noise;
  tmp.convertTo(out, CV_8UC3);
  return out;
}

// A grass-green image with mowing stripes, a few white lines and Gaussian noise.
inline cv::Mat FieldImage(int width, int height, util::Rng& rng, double noise_sigma = 2.0) {
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(kGrass[0], kGrass[1], kGrass[2]));
  for (int x = 0; x < width; x += 160) {
    cv::rectangle(img, cv::Rect(x, 0, 80, height), cv::Scalar(45, 125, 55), cv::FILLED);
  }
  cv::line(img, {0, height / 3}, {width - 1, height / 3 + 40}, cv::Scalar(235, 235, 235), 5,
           cv::LINE_AA);
  cv::line(img, {width / 2, 0}, {width / 2 + 30, height - 1}, cv::Scalar(235, 235, 235), 4,
           cv::LINE_AA);
  return noise_sigma > 0 ? WithNoise(img, rng, noise_sigma) : img;
}

// `img` encoded as a JPEG of this quality and decoded again (4:2:0 chroma, block artefacts).
inline cv::Mat JpegRoundTrip(const cv::Mat& img, int quality) {
  std::vector<uchar> buf;
  codecs::ImEncode(".jpg", img, &buf, {cv::IMWRITE_JPEG_QUALITY, quality});
  return codecs::ImDecode(buf, cv::IMREAD_COLOR);
}

// Paints a Lambert-shaded disc of radius r at centre c (pixel coordinates) by 8x8 supersampling;
// `occluder` (if non-empty) is a rectangle painted dark grey in front of it.
inline void PaintDisc(cv::Mat& img, const Eigen::Vector2d& c, double r, cv::Vec3b colour = kOrange,
                      double shading = 0.35) {
  const int ss = 8;
  const int x0 = std::max(0, int(std::floor(c.x() - r - 1)));
  const int x1 = std::min(img.cols - 1, int(std::ceil(c.x() + r + 1)));
  const int y0 = std::max(0, int(std::floor(c.y() - r - 1)));
  const int y1 = std::min(img.rows - 1, int(std::ceil(c.y() + r + 1)));
  const Eigen::Vector3d light = Eigen::Vector3d(-0.4, -0.5, 0.77).normalized();
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      cv::Vec3d acc(0, 0, 0);
      int inside = 0;
      for (int sy = 0; sy < ss; ++sy) {
        for (int sx = 0; sx < ss; ++sx) {
          const double px = x - 0.5 + (sx + 0.5) / ss - c.x();
          const double py = y - 0.5 + (sy + 0.5) / ss - c.y();
          const double q = (px * px + py * py) / (r * r);
          if (q >= 1.0) continue;
          const Eigen::Vector3d n(px / r, py / r, std::sqrt(1.0 - q));
          const double shade = 1.0 - shading + shading * std::max(0.0, n.dot(light));
          for (int k = 0; k < 3; ++k) acc[k] += colour[k] * shade;
          ++inside;
        }
      }
      if (inside == 0) continue;
      cv::Vec3b& p = img.at<cv::Vec3b>(y, x);
      const double cov = double(inside) / (ss * ss);
      for (int k = 0; k < 3; ++k) {
        p[k] = cv::saturate_cast<uint8_t>(acc[k] / (ss * ss) + (1 - cov) * p[k]);
      }
    }
  }
}

// Ray-casts a sphere (centre in the camera frame, radius) through the camera by supersampling
// (pinhole with the camera's distortion ignored: the camera must have none). Returns the
// projection of the centre.
inline Eigen::Vector2d PaintSphere(cv::Mat& img, const camera::Camera& cam,
                                   const Eigen::Vector3d& centre, double radius,
                                   cv::Vec3b colour = kOrange) {
  Eigen::Vector2d uv(cam.fx * centre.x() / centre.z() + cam.cx,
                     cam.fy * centre.y() / centre.z() + cam.cy);
  const double approx_r = cam.fx * radius / centre.norm() * 3.0 + 3;
  const int ss = 6;
  const int x0 = std::max(0, int(uv.x() - approx_r)),
            x1 = std::min(img.cols - 1, int(uv.x() + approx_r));
  const int y0 = std::max(0, int(uv.y() - approx_r)),
            y1 = std::min(img.rows - 1, int(uv.y() + approx_r));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      int inside = 0;
      for (int sy = 0; sy < ss; ++sy) {
        for (int sx = 0; sx < ss; ++sx) {
          const double u = x - 0.5 + (sx + 0.5) / ss, v = y - 0.5 + (sy + 0.5) / ss;
          const Eigen::Vector3d d =
              Eigen::Vector3d((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0).normalized();
          const double along = d.dot(centre);
          const double dist2 = centre.squaredNorm() - along * along;
          inside += dist2 < radius * radius;
        }
      }
      if (inside == 0) continue;
      const double cov = double(inside) / (ss * ss);
      cv::Vec3b& p = img.at<cv::Vec3b>(y, x);
      for (int k = 0; k < 3; ++k) {
        p[k] = cv::saturate_cast<uint8_t>(cov * colour[k] + (1 - cov) * p[k]);
      }
    }
  }
  return uv;
}

}  // namespace fv::detect::test_util
