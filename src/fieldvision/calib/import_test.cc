#include "fieldvision/calib/import.h"

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "fieldvision/calib/pose2sim.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::calib {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(Import, AniposeTomlWithCommentsAndMillimetres) {
  const std::string path = fv::testing::TempDir() + "/calibration.toml";
  std::ofstream(path) << R"([cam_0]  # the left one
name = "A"
size = [ 1280.0, 720.0,]
matrix = [ [ 1000.5, 0.0, 640.25,],
  [ 0.0, 1001.0, 360.0,],
  [ 0.0, 0.0, 1.0,],]
distortions = [ -0.1, 0.02, 0.0, 0.0, 0.0,]
rotation = [ 0.0, 0.0, 0.0,]
translation = [ 0.0, 0.0, 0.0,]

[cam_1]
name = 'B'
size = [ 1280.0, 720.0,]
matrix = [ [ 990.0, 0.0, 641.0,], [ 0.0, 990.0, 361.0,], [ 0.0, 0.0, 1.0,],]
distortions = [ -0.05, 0.01, 0.001, 0.0,]
rotation = [ 0.0, -0.3, 0.0,]
translation = [ -500.0, 0.0, 50.0,]
fisheye = false

[metadata]
adjusted = true
error = 0.42
)";
  const auto cams = ReadCalibrationToml(path, 0.001);
  ASSERT_EQ(cams.size(), 2u);
  EXPECT_EQ(cams[0].name, "A");
  EXPECT_EQ(cams[1].name, "B");
  EXPECT_EQ(cams[0].width, 1280);
  EXPECT_DOUBLE_EQ(cams[0].fx, 1000.5);
  EXPECT_DOUBLE_EQ(cams[0].cx, 640.25);
  EXPECT_DOUBLE_EQ(cams[1].distortion[2], 0.001);
  EXPECT_NEAR(cams[1].cam_from_world.translation.x(), -0.5, 1e-12);
  EXPECT_NEAR(cams[1].CentreInWorld().norm(), std::hypot(0.5, 0.05), 1e-9);

  // Round trip through our writer (metres).
  const std::string out = fv::testing::TempDir() + "/out.toml";
  WriteCalibrationToml(cams, out);
  const auto back = ReadCalibrationToml(out);
  ASSERT_EQ(back.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back[i].name, cams[i].name);
    EXPECT_NEAR(back[i].fy, cams[i].fy, 1e-9);
    EXPECT_LT((back[i].cam_from_world.translation - cams[i].cam_from_world.translation).norm(),
              1e-12);
    EXPECT_LT(geometry::RotationAngleBetween(back[i].cam_from_world.rotation,
                                             cams[i].cam_from_world.rotation),
              1e-12);
  }
  // Names that are no bare TOML keys (a dot would nest the table, a space or quote end it) come
  // back as they were; a dotted header written by hand ([cam.1]) is still a camera.
  std::vector<camera::Camera> odd = cams;
  odd[0].name = "cam.1";
  odd[1].name = "cam 2 \"left\"";
  WriteCalibrationToml(odd, out);
  const auto odd_back = ReadCalibrationToml(out);
  ASSERT_EQ(odd_back.size(), 2u);
  EXPECT_EQ(odd_back[0].name, "cam.1");
  EXPECT_EQ(odd_back[1].name, "cam 2 \"left\"");
  std::ofstream(out)
      << "[rig.cam_1]\nsize = [10, 10]\nmatrix = [[1, 0, 2], [0, 1, 3], [0, 0, 1]]\n";
  const auto nested = ReadCalibrationToml(out);
  ASSERT_EQ(nested.size(), 1u);
  EXPECT_EQ(nested[0].name, "rig.cam_1");
}

TEST(Import, BadTomlNamesFileAndKey) {
  const std::string path = fv::testing::TempDir() + "/bad.toml";
  std::ofstream(path) << "[cam_1]\nname = \"x\"\nmatrix = [[1, 0, 2], [0, 1]]\nsize = [10, 10]\n";
  EXPECT_THAT([&] { ReadCalibrationToml(path); },
              ThrowsMessage<Error>(::testing::AllOf(HasSubstr("bad.toml"), HasSubstr("matrix"))));
  std::ofstream(path) << "[cam_1]\nmatrix = [[1, 0, 2], [0, 1, 3], [0, 0, 1]\n";
  EXPECT_THROW(ReadCalibrationToml(path), Error);  // not closed
  EXPECT_THROW(ReadCalibrationToml(path + ".missing"), Error);
  std::ofstream(path) << "[cam_1]\nname = \"x\"\nsize = [10, 10]\n"
                         "matrix = [[nan, 0, 2], [0, 1, 3], [0, 0, 1]]\n";
  EXPECT_THAT([&] { ReadCalibrationToml(path); },
              ThrowsMessage<Error>(
                  ::testing::AllOf(HasSubstr("matrix"), HasSubstr("not a finite number"))));
  // Three distortion numbers fit no OpenCV model (k1 k2 k3? k1 k2 p1?): not padded, refused.
  std::ofstream(path)
      << "[cam_1]\nname = \"x\"\nsize = [10, 10]\n"
         "matrix = [[1, 0, 2], [0, 1, 3], [0, 0, 1]]\ndistortions = [0.1, 0.2, 0.3]\n";
  EXPECT_THAT([&] { ReadCalibrationToml(path); },
              ThrowsMessage<Error>(
                  ::testing::AllOf(HasSubstr("[cam_1]"), HasSubstr("distortions has 3 numbers"))));
  // A key given twice is not TOML (the last one used to win): file and line named.
  std::ofstream(path) << "[cam_1]\nname = \"x\"\nsize = [10, 10]\n"
                         "matrix = [[1, 0, 2], [0, 1, 3], [0, 0, 1]]\nname = \"y\"\n";
  EXPECT_THAT([&] { ReadCalibrationToml(path); },
              ThrowsMessage<Error>(::testing::AllOf(HasSubstr("bad.toml:5"), HasSubstr("name"))));
  // Cameras come in file order, whatever their sections' names.
  std::ofstream(path) << "[cam_2]\nname = \"first\"\nsize = [10, 10]\n"
                         "matrix = [[1, 0, 2], [0, 1, 3], [0, 0, 1]]\n"
                         "[cam_1]\nsize = [10, 10]\nmatrix = [[1, 0, 2], [0, 1, 3], [0, 0, 1]]\n";
  const auto ordered = ReadCalibrationToml(path);
  ASSERT_EQ(ordered.size(), 2u);
  EXPECT_EQ(ordered[0].name, "first");
  EXPECT_EQ(ordered[1].name, "cam_1");
  // A camera's section without its matrix is named, not left out (the others were imported).
  std::ofstream(path) << "[cam_2]\nname = \"first\"\nsize = [10, 10]\n"
                         "matrix = [[1, 0, 2], [0, 1, 3], [0, 0, 1]]\n"
                         "[cam_1]\nsize = [10, 10]\ndistortions = [0.1, 0.2]\n"
                         "rotation = [0, 0, 0]\ntranslation = [0, 0, 1]\n"
                         "[metadata]\nadjusted = false\n";
  EXPECT_THAT([&] { ReadCalibrationToml(path); },
              ThrowsMessage<Error>(::testing::AllOf(HasSubstr("[cam_1]"),
                                                    HasSubstr("key 'matrix' is missing"))));
  // k1 k2 alone: the radial terms, the rest 0.
  std::ofstream(path) << "[cam_1]\nname = \"x\"\nsize = [10, 10]\n"
                         "matrix = [[1, 0, 2], [0, 1, 3], [0, 0, 1]]\ndistortions = [0.1, 0.2]\n";
  EXPECT_EQ(ReadCalibrationToml(path).front().distortion, (std::vector<double>{0.1, 0.2, 0, 0}));
  // A camera given twice would be written as two tables of one name (not TOML).
  camera::Camera cam = camera::Camera::FromFov(64, 48, 60);
  cam.name = "same";
  cam.has_pose = true;
  EXPECT_THAT(
      [&] {
        WriteCalibrationToml({cam, cam}, path + ".out");
      },
      ThrowsMessage<Error>(HasSubstr("two cameras are named 'same'")));
  EXPECT_FALSE(std::filesystem::exists(path + ".out"));
  int w = 0, h = 0;
  ParseImageSize("1920x1080", "size", &w, &h);
  EXPECT_EQ(w, 1920);
  EXPECT_EQ(h, 1080);
  EXPECT_THROW(ParseImageSize("1920", "size", &w, &h), Error);
  EXPECT_THROW(ParseImageSize("1920x1080x3", "size", &w, &h), Error);
  ParseImageSize("65536x10", "size", &w, &h);
  EXPECT_THAT(
      [&] { ParseImageSize("100000x10", "--image-size", &w, &h); },
      ThrowsMessage<Error>(HasSubstr("--image-size '100000x10' is over the limit of 65536")));
}

TEST(Import, OpenCvStereoFiles) {
  const std::string dir = fv::testing::TempDir();
  {
    cv::FileStorage fs(dir + "/extrinsics.yml", cv::FileStorage::WRITE);
    const cv::Mat r = (cv::Mat_<double>(3, 3) << 1, 0, 0, 0, 0.99995, -0.01, 0, 0.01, 0.99995);
    const cv::Mat t = (cv::Mat_<double>(3, 1) << -3.3, 0.04, -0.01);  // squares
    fs << "R" << r << "T" << t;
  }
  std::vector<std::string> files = {dir + "/extrinsics.yml"};
  const std::string data = fv::testing::SharedDataDir();
  if (data.empty()) {
    cv::FileStorage fs(dir + "/intrinsics.yml", cv::FileStorage::WRITE);
    const cv::Mat m = (cv::Mat_<double>(3, 3) << 534.8, 0, 335.7, 0, 534.8, 240.7, 0, 0, 1);
    const cv::Mat d = (cv::Mat_<double>(1, 5) << 0.1, -0.2, 0, 0, 0);
    fs << "M1" << m << "D1" << d << "M2" << m << "D2" << d;
    files.insert(files.begin(), dir + "/intrinsics.yml");
  } else {
    files.insert(files.begin(), data + "/opencv-chessboard/intrinsics.yml");
  }
  const auto cams = ReadOpenCvStereo(files, 640, 480, 0.025);
  ASSERT_EQ(cams.size(), 2u);
  EXPECT_NEAR(cams[0].fx, 534.8, 0.1);
  EXPECT_EQ(cams[1].width, 640);
  EXPECT_TRUE(cams[0].cam_from_world.translation.isZero());
  EXPECT_NEAR(cams[1].CentreInWorld().norm(), 0.025 * std::sqrt(3.3 * 3.3 + 0.04 * 0.04 + 1e-4),
              1e-9);
  EXPECT_THROW(ReadOpenCvStereo({dir + "/extrinsics.yml"}, 640, 480), Error);  // no M1
  EXPECT_THROW(ReadOpenCvStereo(files, 0, 480), Error);
}

}  // namespace
}  // namespace fv::calib
