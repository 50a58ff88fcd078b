#include "fieldvision/detect/lab.h"

#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::detect {
namespace {

TEST(BgrToLab, ThreadsConvertingWhileTheTablesBuildGetOpenCvsValues) {
  testing::SeededRng rng(31);
  std::vector<cv::Mat> images;
  for (int t = 0; t < 4; ++t) {
    cv::Mat bgr(24, 32, CV_8UC3);
    for (int y = 0; y < bgr.rows; ++y) {
      for (int x = 0; x < bgr.cols; ++x) {
        bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(rng.UniformInt(0, 255)),
                                            static_cast<uint8_t>(rng.UniformInt(0, 255)),
                                            static_cast<uint8_t>(rng.UniformInt(0, 255)));
      }
    }
    images.push_back(bgr);
  }
  std::vector<cv::Mat> labs(images.size());
  {
    const std::future<void> tables = PrepareBgrToLab();
    std::vector<std::thread> threads;
    for (size_t t = 0; t < images.size(); ++t) {
      threads.emplace_back([&, t] { BgrToLab(images[t], &labs[t]); });
    }
    for (std::thread& th : threads) th.join();
  }
  for (size_t t = 0; t < images.size(); ++t) {
    cv::Mat want;
    cv::cvtColor(images[t], want, cv::COLOR_BGR2Lab);
    ASSERT_EQ(labs[t].size(), want.size());
    EXPECT_EQ(cv::norm(labs[t], want, cv::NORM_INF), 0.0) << "image " << t;
  }
}

TEST(BgrToLab, EmptyInEmptyOutAndOtherTypesThrow) {
  cv::Mat lab(2, 2, CV_8UC3);
  BgrToLab(cv::Mat(), &lab);
  EXPECT_TRUE(lab.empty());
  EXPECT_THROW(BgrToLab(cv::Mat(2, 2, CV_8UC1), &lab), Error);
  EXPECT_THROW(BgrToLab(cv::Mat(2, 2, CV_8UC3), nullptr), Error);
}

}  // namespace
}  // namespace fv::detect
