#include "fieldvision/detect/blobs.h"

#include <map>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

using test_util::kGrass;
using test_util::kOrange;

// Random orange and green pixels in clumps: a hard case for run merging.
cv::Mat RandomClumps(util::Rng& rng, int w, int h) {
  cv::Mat small(h / 3, w / 3, CV_8UC3);
  for (int y = 0; y < small.rows; ++y) {
    for (int x = 0; x < small.cols; ++x) {
      small.at<cv::Vec3b>(y, x) = rng.Uniform() < 0.35 ? kOrange : kGrass;
    }
  }
  cv::Mat img;
  cv::resize(small, img, cv::Size(w, h), 0, 0, cv::INTER_NEAREST);
  // Single stray pixels and diagonal touches.
  for (int i = 0; i < 200; ++i) {
    img.at<cv::Vec3b>(rng.UniformInt(0, h - 1), rng.UniformInt(0, w - 1)) = kOrange;
  }
  return img;
}

TEST(ScanBlobs, StepOneEqualsOpenCvConnectedComponents) {
  const uint64_t seed = fv::testing::TestSeed(11);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  const cv::Mat img = RandomClumps(rng, 150, 120);
  ScanOptions o;
  o.step_px = 1;
  o.min_samples = 1;
  const BlobScanResult r = ScanBlobs(img, table, table.BallBit(), o);
  cv::Mat bin = table.ClassifyImage(img) & table.BallBit();
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(bin > 0, labels, stats, centroids, 8);
  ASSERT_EQ(static_cast<int>(r.blobs.size()), n - 1);
  std::multiset<std::tuple<int, int, int, int, int>> ours, theirs;
  for (const Blob& b : r.blobs) ours.insert({b.samples, b.x_min, b.y_min, b.x_max, b.y_max});
  for (int i = 1; i < n; ++i) {
    const int* s = stats.ptr<int>(i);
    theirs.insert({s[cv::CC_STAT_AREA], s[cv::CC_STAT_LEFT], s[cv::CC_STAT_TOP],
                   s[cv::CC_STAT_LEFT] + s[cv::CC_STAT_WIDTH] - 1,
                   s[cv::CC_STAT_TOP] + s[cv::CC_STAT_HEIGHT] - 1});
  }
  EXPECT_EQ(ours, theirs);
  // Moments: the centroid of the largest blob equals OpenCV's.
  const Blob& big = r.blobs.front();
  bool found = false;
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) == big.samples &&
        stats.at<int>(i, cv::CC_STAT_LEFT) == big.x_min &&
        stats.at<int>(i, cv::CC_STAT_TOP) == big.y_min) {
      EXPECT_NEAR(big.centroid_px().x(), centroids.at<double>(i, 0), 1e-9);
      EXPECT_NEAR(big.centroid_px().y(), centroids.at<double>(i, 1), 1e-9);
      found = true;
    }
  }
  EXPECT_TRUE(found);
}

TEST(ScanBlobs, CoarseStepFindsEachDiscOnceWithItsSize) {
  const uint64_t seed = fv::testing::TestSeed(5);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  cv::Mat img = test_util::FieldImage(640, 480, rng);
  std::vector<std::pair<Eigen::Vector2d, double>> discs;
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector2d c(60 + 100 * i + rng.Uniform(0, 1), rng.Uniform(60, 420));
    const double r = rng.Uniform(4, 30);
    test_util::PaintDisc(img, c, r);
    discs.push_back({c, r});
  }
  for (int step : {2, 4}) {
    SCOPED_TRACE(step);
    ScanOptions o;
    o.step_px = step;
    const BlobScanResult res = ScanBlobs(img, table, table.BallBit(), o);
    ASSERT_EQ(res.blobs.size(), discs.size()) << res.Summary();
    for (const auto& [c, r] : discs) {
      int matches = 0;
      for (const Blob& b : res.blobs) {
        if ((b.centroid_px() - c).norm() < 0.3 * r + step) {
          ++matches;
          EXPECT_NEAR(b.equivalent_radius_px(), r, 0.15 * r + step);
          EXPECT_NEAR(b.fill_ratio(), M_PI / 4, 0.25);
          // 3 by 2 samples of a small disc at step 4; a disc under 2 steps in radius can show
          // in one row only, its edge rows' short chords not classified (r 4.4 at seed 56).
          EXPECT_LE(b.aspect_ratio(), r < 2 * step ? 2.0 : 1.5) << "r " << r;
        }
      }
      EXPECT_EQ(matches, 1) << "disc at " << c.transpose() << " r " << r;
    }
  }
  // A mask hides what is outside it.
  cv::Mat mask(img.size(), CV_8U, cv::Scalar(0));
  mask(cv::Rect(0, 0, 320, 480)).setTo(255);
  const BlobScanResult half = ScanBlobs(img, table, table.BallBit(), ScanOptions{}, mask);
  for (const Blob& b : half.blobs) EXPECT_LT(b.x_max, 320);
  EXPECT_LT(half.blobs.size(), discs.size());
}

// Every step, image width (down to one sample a row) and region: the blobs are the 8-connected
// components of the table's classes on the sample grid (ColourTable::ClassifyImage), with their
// sample counts and bounds; for the exact and a quantised table.
TEST(ScanBlobs, SampleGridComponentsForEveryStepWidthAndRegion) {
  const uint64_t seed = fv::testing::TestSeed(23);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  for (int bits : {8, 6}) {
    const ColourTable table(PresetColourSpec("orange"), bits);
    for (int trial = 0; trial < 60; ++trial) {
      const int w = rng.UniformInt(1, 70), h = rng.UniformInt(1, 40);
      cv::Mat img(h, w, CV_8UC3);
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          img.at<cv::Vec3b>(y, x) = rng.Uniform() < 0.4 ? kOrange : kGrass;
        }
      }
      const int step = rng.UniformInt(1, 5);
      const int rx = rng.UniformInt(0, w - 1), ry = rng.UniformInt(0, h - 1);
      const cv::Rect region =
          trial % 2 == 0 ? cv::Rect()
                         : cv::Rect(rx, ry, rng.UniformInt(1, w - rx), rng.UniformInt(1, h - ry));
      SCOPED_TRACE(::testing::Message() << "bits " << bits << " " << w << "x" << h << " step "
                                        << step << " region " << region);
      ScanOptions o;
      o.step_px = step;
      o.min_samples = 1;
      const BlobScanResult r = ScanBlobs(img, table, table.BallBit(), o, cv::Mat(), region);
      // The reference: the class on the grid offset + k * step within the region.
      const cv::Rect roi = region.empty() ? cv::Rect(0, 0, w, h) : region;
      const cv::Mat cls = table.ClassifyImage(img);
      std::vector<int> xs, ys;
      for (int x = step / 2; x < w; x += step) {
        if (x >= roi.x && x < roi.x + roi.width) xs.push_back(x);
      }
      for (int y = step / 2; y < h; y += step) {
        if (y >= roi.y && y < roi.y + roi.height) ys.push_back(y);
      }
      std::multiset<std::tuple<int, int, int, int, int>> ours, theirs;
      for (const Blob& b : r.blobs) ours.insert({b.samples, b.x_min, b.y_min, b.x_max, b.y_max});
      if (!xs.empty() && !ys.empty()) {
        cv::Mat grid(static_cast<int>(ys.size()), static_cast<int>(xs.size()), CV_8U);
        for (size_t j = 0; j < ys.size(); ++j) {
          for (size_t i = 0; i < xs.size(); ++i) {
            grid.at<uint8_t>(j, i) = (cls.at<uint8_t>(ys[j], xs[i]) & table.BallBit()) ? 255 : 0;
          }
        }
        cv::Mat labels, stats, centroids;
        const int n = cv::connectedComponentsWithStats(grid, labels, stats, centroids, 8);
        for (int i = 1; i < n; ++i) {
          const int* s = stats.ptr<int>(i);
          const int x0 = s[cv::CC_STAT_LEFT], y0 = s[cv::CC_STAT_TOP];
          theirs.insert({s[cv::CC_STAT_AREA], xs[x0], ys[y0], xs[x0 + s[cv::CC_STAT_WIDTH] - 1],
                         ys[y0 + s[cv::CC_STAT_HEIGHT] - 1]});
        }
      }
      EXPECT_EQ(ours, theirs);
      EXPECT_EQ(r.samples, static_cast<long long>(xs.size() * ys.size()));
    }
  }
}

TEST(ScanBlobs, OptionsAreChecked) {
  ScanOptions o;
  o.step_px = 0;
  EXPECT_THROW(o.Check(), Error);
  const ColourTable table(PresetColourSpec("orange"), 6);
  EXPECT_THROW(ScanBlobs(cv::Mat(), table, 1, ScanOptions{}), Error);
}

}  // namespace
}  // namespace fv::detect
