#include "fieldvision/detect/eval_drawing.h"

#include <gtest/gtest.h>

#include "fieldvision/util/error.h"

namespace fv::detect {
namespace {

// Whether the drawing has a pixel near `colour` (each channel within 60) in `roi`.
bool HasColour(const cv::Mat& img, cv::Rect roi, cv::Vec3b colour) {
  roi &= cv::Rect(0, 0, img.cols, img.rows);
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      const cv::Vec3b& p = img.at<cv::Vec3b>(y, x);
      if (std::abs(p[0] - colour[0]) < 60 && std::abs(p[1] - colour[1]) < 60 &&
          std::abs(p[2] - colour[2]) < 60) {
        return true;
      }
    }
  }
  return false;
}

TEST(EvalDrawing, SmallImagesAreEnlargedByAWholeFactor) {
  EXPECT_EQ(EvalDrawingScale(224, 224), 3);
  EXPECT_EQ(EvalDrawingScale(608, 800), 1);
  EXPECT_EQ(EvalDrawingScale(1280, 960), 1);
  EXPECT_EQ(EvalDrawingScale(100, 80), 6);
  EXPECT_EQ(EvalDrawingScale(1, 1), 8);
}

// The box, its hit area and the candidates land where they are in the enlarged frame, between a
// band of wrapped title lines and a legend.
TEST(EvalDrawing, BoxCandidatesTitleAndLegend) {
  const cv::Mat grey(80, 100, CV_8UC3, cv::Scalar::all(128));
  BallCandidate accepted, rejected;
  accepted.centre_px = Eigen::Vector2d(60, 40);
  accepted.radius_px = 8;
  accepted.accepted = true;
  accepted.score = 0.9;
  rejected.centre_px = Eigen::Vector2d(20, 20);
  rejected.radius_px = 5;
  std::string reason = "miss:";
  for (int i = 0; i < 30; ++i) reason += " word";  // 155 characters: two lines at 600 px
  const std::vector<std::string> title = {"image.png", reason};
  const cv::Mat d =
      DrawEvalImage(grey, {cv::Rect2d(50, 30, 20, 20)}, 0.25, {accepted, rejected}, title);
  const int k = 6;
  ASSERT_EQ(d.cols, 100 * k);
  ASSERT_GT(d.rows, 80 * k + 3 * 18);  // at least three title lines and a legend line
  // The frame starts below the title band: find its first grey row.
  int top = 0;
  while (top < d.rows && d.at<cv::Vec3b>(top, d.cols / 2) != cv::Vec3b(128, 128, 128)) ++top;
  ASSERT_GE(top, 3 * 18) << "title band of three lines";
  const auto at = [&](double x, double y) {
    return cv::Point(cvRound(k * x + 0.5 * (k - 1)), top + cvRound(k * y + 0.5 * (k - 1)));
  };
  const cv::Vec3b cyan(255, 255, 0), green(0, 255, 0), red(0, 0, 255);
  EXPECT_TRUE(HasColour(d, cv::Rect(at(50, 40) - cv::Point(3, 3), cv::Size(7, 7)), cyan));
  EXPECT_TRUE(HasColour(d, cv::Rect(at(45, 40) - cv::Point(3, 3), cv::Size(7, 7)), cyan))
      << "the grown box (25 % each side)";
  EXPECT_FALSE(HasColour(d, cv::Rect(at(40, 40) - cv::Point(3, 3), cv::Size(7, 7)), cyan));
  EXPECT_TRUE(HasColour(d, cv::Rect(at(68, 40) - cv::Point(3, 3), cv::Size(7, 7)), green));
  EXPECT_TRUE(HasColour(d, cv::Rect(at(25, 20) - cv::Point(3, 3), cv::Size(7, 7)), red));
  EXPECT_TRUE(HasColour(d, cv::Rect(0, 0, d.cols, top), cv::Vec3b(255, 255, 255)));
  EXPECT_TRUE(HasColour(d, cv::Rect(0, top + 80 * k, d.cols, d.rows - top - 80 * k),
                        cv::Vec3b(255, 255, 255)))
      << "legend";
  EXPECT_THROW(DrawEvalImage(cv::Mat(), {}, 0.25, {}, {}), Error);
}

}  // namespace
}  // namespace fv::detect
