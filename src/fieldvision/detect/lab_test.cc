#include "fieldvision/detect/lab.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

cv::Mat RandomImage(testing::SeededRng& rng, int rows, int cols) {
  cv::Mat bgr(rows, cols, CV_8UC3);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(rng.UniformInt(0, 255)),
                                          static_cast<uint8_t>(rng.UniformInt(0, 255)),
                                          static_cast<uint8_t>(rng.UniformInt(0, 255)));
    }
  }
  return bgr;
}

// Published CIELAB of the sRGB primaries and greys (L 53.24, a 80.09, b 67.20 for red, ...), in
// the 8-bit convention.
TEST(BgrToLab, ReferenceColours) {
  const std::vector<std::pair<cv::Vec3b, cv::Vec3b>> cases = {
      {{0, 0, 255}, {136, 208, 195}}, {{0, 255, 0}, {224, 42, 211}},
      {{255, 0, 0}, {82, 207, 20}},   {{255, 255, 255}, {255, 128, 128}},
      {{0, 0, 0}, {0, 128, 128}},     {{128, 128, 128}, {137, 128, 128}}};
  for (const auto& [bgr, want] : cases) {
    cv::Mat lab;
    BgrToLab(cv::Mat(1, 1, CV_8UC3, cv::Scalar(bgr[0], bgr[1], bgr[2])), &lab);
    EXPECT_EQ(lab.at<cv::Vec3b>(0, 0), want) << "BGR " << bgr;
  }
}

TEST(BgrToLab, WithinThreeLevelsOfOpenCvAndTheSameOnEveryThread) {
  const uint64_t seed = testing::TestSeed(31);
  FV_SEED_TRACE(seed);
  testing::SeededRng rng(seed);
  std::vector<cv::Mat> images;
  images.reserve(4);
  for (int t = 0; t < 4; ++t) images.push_back(RandomImage(rng, 64, 64));
  std::vector<cv::Mat> labs(images.size());
  std::vector<std::thread> threads;  // the first conversions at once: the table is built once
  for (size_t t = 0; t < images.size(); ++t) {
    threads.emplace_back([&, t] { BgrToLab(images[t], &labs[t]); });
  }
  for (std::thread& th : threads) th.join();
  for (size_t t = 0; t < images.size(); ++t) {
    cv::Mat opencv, again;
    cv::cvtColor(images[t], opencv, cv::COLOR_BGR2Lab);  // interpolated tables: off by up to 3
    ASSERT_EQ(labs[t].size(), opencv.size());
    EXPECT_LE(cv::norm(labs[t], opencv, cv::NORM_INF), 3.0) << "image " << t;
    EXPECT_LT(cv::norm(labs[t], opencv, cv::NORM_L1) / (3.0 * labs[t].total()), 0.25);
    BgrToLab(images[t], &again);
    EXPECT_EQ(cv::norm(labs[t], again, cv::NORM_INF), 0.0) << "image " << t;
  }
  // A view into a larger image converts as the same pixels on their own.
  cv::Mat part;
  BgrToLab(images[0](cv::Rect(5, 7, 20, 9)), &part);
  EXPECT_EQ(cv::norm(part, labs[0](cv::Rect(5, 7, 20, 9)), cv::NORM_INF), 0.0);
}

// The CIE 1976 definition in 8 bits, straight from the standards' formulas (std::pow, std::cbrt).
cv::Vec3b DefinitionLab(const cv::Vec3b& bgr) {
  auto linear = [](int v) {
    const double c = v / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  auto f = [](double t) { return t > 0.008856 ? std::cbrt(t) : 7.787 * t + 16.0 / 116.0; };
  auto level = [](double v) { return static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L)); };
  const double b = linear(bgr[0]), g = linear(bgr[1]), r = linear(bgr[2]);
  const double fx = f((0.412453 * r + 0.357580 * g + 0.180423 * b) / 0.950456);
  const double fy = f(0.212671 * r + 0.715160 * g + 0.072169 * b);
  const double fz = f((0.019334 * r + 0.119193 * g + 0.950227 * b) / 1.088754);
  return {level((116.0 * fy - 16.0) * 255.0 / 100.0), level(500.0 * (fx - fy) + 128.0),
          level(200.0 * (fy - fz) + 128.0)};
}

TEST(BgrToLab, TheDefinitionOnEveryThirdLevelOfEachChannel) {
  std::vector<int> levels;
  levels.reserve(86);  // 0, 3, ..., 252 and 255
  for (int v = 0; v < 255; v += 3) levels.push_back(v);
  levels.push_back(255);
  cv::Mat bgr(static_cast<int>(levels.size() * levels.size()), static_cast<int>(levels.size()),
              CV_8UC3);
  for (size_t i = 0; i < levels.size(); ++i) {
    for (size_t j = 0; j < levels.size(); ++j) {
      for (size_t k = 0; k < levels.size(); ++k) {
        bgr.at<cv::Vec3b>(static_cast<int>(i * levels.size() + j), static_cast<int>(k)) =
            cv::Vec3b(levels[i], levels[j], levels[k]);
      }
    }
  }
  cv::Mat lab;
  BgrToLab(bgr, &lab);
  int differ = 0;
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b want = DefinitionLab(bgr.at<cv::Vec3b>(y, x));
      if (lab.at<cv::Vec3b>(y, x) != want && ++differ <= 3) {
        ADD_FAILURE() << "BGR " << bgr.at<cv::Vec3b>(y, x) << ": " << lab.at<cv::Vec3b>(y, x)
                      << ", the definition " << want;
      }
    }
  }
  EXPECT_EQ(differ, 0);
}

TEST(BgrToLab, EmptyInEmptyOutAndOtherTypesThrow) {
  cv::Mat lab(2, 2, CV_8UC3);
  BgrToLab(cv::Mat(), &lab);
  EXPECT_TRUE(lab.empty());
  EXPECT_THROW(BgrToLab(cv::Mat(2, 2, CV_8UC1), &lab), Error);
  EXPECT_THROW(BgrToLab(cv::Mat(2, 2, CV_8UC3), nullptr), Error);
  cv::Mat same(2, 2, CV_8UC3);
  EXPECT_THROW(BgrToLab(same, &same), Error);
}

}  // namespace
}  // namespace fv::detect
