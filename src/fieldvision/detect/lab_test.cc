#include "fieldvision/detect/lab.h"

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
