// The circle from colour edges near an expected one: a shaded yellow ball with a printed cross
// in front of a yellow board (one colour class for both) is outlined to a fraction of a pixel
// from an expectation 1.5 px and 10 % off; an empty board, an expectation far off in size and
// bad options give no circle or an error.
#include "fieldvision/detect/edge_circle.h"

#include <algorithm>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

using Eigen::Vector2d;

TEST(FitEdgeCircle, OutlinesAPrintedBallInFrontOfABoardOfItsColour) {
  const uint64_t seed = fv::testing::TestSeed(31);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const cv::Vec3b board(20, 200, 230), ball(10, 175, 205);  // BGR: both yellow
  std::vector<double> errors;
  constexpr int kTrials = 30;
  for (int i = 0; i < kTrials; ++i) {
    cv::Mat img(160, 160, CV_8UC3, cv::Scalar(board[0], board[1], board[2]));
    cv::Mat noise(img.size(), CV_8UC3);
    test_util::FillNormal(noise, rng, 0, 2);
    const Vector2d c(rng.Uniform(60, 100), rng.Uniform(60, 100));
    const double r = rng.Uniform(5, 20);
    test_util::PaintDisc(img, c, r, ball, 0.5);
    // A dark print: two lines across the ball.
    const double a = rng.Uniform(0, M_PI);
    for (const double da : {0.0, M_PI / 2}) {
      const Vector2d d(std::cos(a + da), std::sin(a + da));
      const Vector2d p0 = c - 0.7 * r * d, p1 = c + 0.7 * r * d;
      cv::line(img, cv::Point2d(p0.x(), p0.y()), cv::Point2d(p1.x(), p1.y()),
               cv::Scalar(20, 40, 40), std::max(1, static_cast<int>(r / 8)), cv::LINE_AA);
    }
    img += noise;
    const Vector2d expected = c + 1.5 * Vector2d(std::cos(3.0 * i), std::sin(3.0 * i));
    const EdgeCircle e = FitEdgeCircle(img, expected, 1.1 * r);
    ASSERT_TRUE(e.ok) << "trial " << i << " r " << r;
    EXPECT_NEAR(e.radius_px, r, 0.1 * r + 0.3) << "trial " << i;
    EXPECT_GT(e.inlier_fraction, 0.6) << "trial " << i;
    EXPECT_GT(e.sigma_px, 0.0);
    errors.push_back((e.centre_px - c).norm());
    // Twice the size: no circle of that radius agrees.
    EXPECT_FALSE(FitEdgeCircle(img, expected, 2.0 * r).ok) << "trial " << i;
  }
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.25);
  EXPECT_LT(errors.back(), 0.8);
}

TEST(FitEdgeCircle, NothingOnAnEmptyBoardAndBadOptionsAreNamed) {
  cv::Mat img(100, 100, CV_8UC3, cv::Scalar(20, 200, 230));
  cv::Mat noise(img.size(), CV_8UC3);
  util::Rng rng(fv::testing::TestSeed(32));
  test_util::FillNormal(noise, rng, 0, 3);
  img += noise;
  EXPECT_FALSE(FitEdgeCircle(img, Vector2d(50, 50), 10).ok);
  EXPECT_FALSE(FitEdgeCircle(img, Vector2d(2, 2), 10).ok);  // rays leave the image
  EXPECT_FALSE(FitEdgeCircle(img, Vector2d(50, std::nan("")), 10).ok);
  EdgeCircleOptions bad;
  bad.ransac_iterations = 0;
  try {
    FitEdgeCircle(img, Vector2d(50, 50), 10, bad);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ransac_iterations"), std::string::npos);
  }
  EXPECT_THROW(FitEdgeCircle(cv::Mat(10, 10, CV_8U), Vector2d(5, 5), 2), Error);
}

}  // namespace
}  // namespace fv::detect
