// The blob path of colour segmentation as in RoboCup vision systems: every step-th row is
// scanned at every step-th column, each sample is classified with the colour lookup table,
// samples of the wanted classes form run-length-encoded runs, and runs touching runs of the
// previous scanned row (8-connected on the sample grid) are merged with union-find into blobs
// with their moments and bounding boxes. Written by hand because it is the product's fast path
// (a fraction of the pixels, no colour conversion); OpenCV's connectedComponents needs a full
// binary image first.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/detect/colour.h"

namespace fv::detect {

struct ScanOptions {
  int step_px = 2;      // sample every step-th row and column (1 = every pixel)
  int min_samples = 2;  // blobs with fewer samples are dropped
  // Throws fv::Error naming the bad field.
  void Check() const;
};

// A run of samples of the class on one scanned row; x0..x1 inclusive, full-resolution pixels.
struct Run {
  int y = 0;
  int x0 = 0;
  int x1 = 0;
};

// A blob of merged runs. Bounds are those of the samples; the blob covers about half a step more
// on each side. Moments are over samples, each standing for step x step pixels.
struct Blob {
  int x_min = 0, x_max = 0, y_min = 0, y_max = 0;
  int samples = 0;
  int runs = 0;
  int step_px = 1;
  double sum_x = 0, sum_y = 0, sum_xx = 0, sum_yy = 0, sum_xy = 0;

  double area_px() const { return double(samples) * step_px * step_px; }
  double width_px() const { return x_max - x_min + step_px; }
  double height_px() const { return y_max - y_min + step_px; }
  Eigen::Vector2d centroid_px() const { return {sum_x / samples, sum_y / samples}; }
  // area / bounding-box area: pi/4 for a disc.
  double fill_ratio() const { return area_px() / (width_px() * height_px()); }
  // max(w, h) / min(w, h): 1 for a disc.
  double aspect_ratio() const;
  // Radius of the disc with the blob's area.
  double equivalent_radius_px() const;
};

struct BlobScanResult {
  std::vector<Blob> blobs;  // largest first
  int runs = 0;
  long long samples = 0;  // pixels classified
  std::string Summary() const;
};

// Scans `bgr` (CV_8UC3) for samples whose class bits intersect `class_mask`. `mask` (optional,
// CV_8U, same size): samples where it is 0 are ignored. `region` (optional): only the samples
// inside it (on the same grid as the whole image), in whole-image coordinates.
BlobScanResult ScanBlobs(const cv::Mat& bgr, const ColourTable& table, uint8_t class_mask,
                         const ScanOptions& options, const cv::Mat& mask = cv::Mat(),
                         const cv::Rect& region = cv::Rect());

}  // namespace fv::detect
