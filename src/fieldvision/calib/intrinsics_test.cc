#include "fieldvision/calib/intrinsics.h"

#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::calib {
namespace {

// Reads a matrix from an OpenCV YAML reference file.
cv::Mat ReadRef(const std::string& path, const char* key) {
  cv::FileStorage fs(path, cv::FileStorage::READ);
  cv::Mat m;
  fs[key] >> m;
  return m;
}

TEST(Intrinsics, OpenCvLeftChessboardMatchesReference) {
  const std::string data = fv::testing::SharedDataDir();
  if (data.empty()) GTEST_SKIP() << "no shared data";
  const std::string dir = data + "/opencv-chessboard";
  IntrinsicsOptions o;
  o.board = {BoardType::kChessboard, 9, 6, 0.025};
  o.progress = false;
  // The reference was made by OpenCV's calibration sample: CALIB_FIX_ASPECT_RATIO and an
  // uncapped 11 px cornerSubPix half window.
  o.fix_aspect_ratio = true;
  o.detect.subpix_half_window_px = 11;
  o.detect.subpix_square_fraction = 0.0;
  const IntrinsicsResult r = CalibrateIntrinsics(dir + "/left*.jpg", o);
  const std::string ref = dir + "/left_intrinsics.yml";
  const cv::Mat k = ReadRef(ref, "camera_matrix");
  cv::FileStorage fs(ref, cv::FileStorage::READ);
  const double ref_rms = static_cast<double>(fs["avg_reprojection_error"]);
  EXPECT_EQ(r.num_images, 13);
  EXPECT_EQ(r.num_used, 13) << r.Summary();
  EXPECT_NEAR(r.camera.fx, k.at<double>(0, 0), 0.005 * k.at<double>(0, 0));
  EXPECT_NEAR(r.camera.fy, k.at<double>(1, 1), 0.005 * k.at<double>(1, 1));
  EXPECT_NEAR(r.camera.cx, k.at<double>(0, 2), 0.005 * k.at<double>(0, 2));
  EXPECT_NEAR(r.camera.cy, k.at<double>(1, 2), 0.005 * k.at<double>(1, 2));
  EXPECT_NEAR(r.rms_px, ref_rms, 0.05);
  EXPECT_EQ(r.camera.width, 640);
  EXPECT_EQ(r.camera.height, 480);
  EXPECT_EQ(r.camera.notes.at("board"), o.board.Describe());
}

TEST(Intrinsics, DefaultsFitTheLeftViewsBetterThanTheReference) {
  // Our default caps the cornerSubPix window at 45 % of a square: the reference's 23 px window
  // reaches the neighbouring corners in left02 (its view error is 1.18 px there).
  const std::string data = fv::testing::SharedDataDir();
  if (data.empty()) GTEST_SKIP() << "no shared data";
  const std::string dir = data + "/opencv-chessboard";
  IntrinsicsOptions o;
  o.board = {BoardType::kChessboard, 9, 6, 0.025};
  o.progress = false;
  const IntrinsicsResult r = CalibrateIntrinsics(dir + "/left*.jpg", o);
  const cv::Mat k = ReadRef(dir + "/left_intrinsics.yml", "camera_matrix");
  EXPECT_EQ(r.num_used, 13) << r.Summary();
  EXPECT_LT(r.rms_px, 0.3) << r.Summary();
  EXPECT_NEAR(r.camera.fx, k.at<double>(0, 0), 0.01 * k.at<double>(0, 0));
  EXPECT_NEAR(r.camera.fy, k.at<double>(1, 1), 0.01 * k.at<double>(1, 1));
  EXPECT_NEAR(r.camera.cx, k.at<double>(0, 2), 0.01 * k.at<double>(0, 2));
  EXPECT_NEAR(r.camera.cy, k.at<double>(1, 2), 0.01 * k.at<double>(1, 2));
}

}  // namespace
}  // namespace fv::calib
