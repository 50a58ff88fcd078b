#include "fieldvision/camera/camera.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/camera/opencv_camera.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::camera {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// A camera 20 m from the field centre with plausible distortion of `n` coefficients.
Camera RandomCamera(util::Rng& rng, int n) {
  Camera cam = Camera::FromFov(1280, 960, rng.Uniform(50, 90));
  cam.cx += rng.Uniform(-20, 20);
  cam.cy += rng.Uniform(-20, 20);
  cam.fy *= rng.Uniform(0.98, 1.02);
  const double full[kNumDistortion] = {
      rng.Uniform(-0.3, 0.1),   rng.Uniform(-0.05, 0.05), rng.Uniform(-1e-3, 1e-3),
      rng.Uniform(-1e-3, 1e-3), rng.Uniform(-0.01, 0.01), rng.Uniform(-0.05, 0.05),
      rng.Uniform(-0.01, 0.01), rng.Uniform(-0.01, 0.01), rng.Uniform(-1e-3, 1e-3),
      rng.Uniform(-1e-4, 1e-4), rng.Uniform(-1e-3, 1e-3), rng.Uniform(-1e-4, 1e-4),
      rng.Uniform(-0.02, 0.02), rng.Uniform(-0.02, 0.02)};
  cam.distortion.assign(full, full + n);
  const Eigen::Vector3d eye(rng.Uniform(-15, 15), rng.Uniform(-12, -8), rng.Uniform(3, 8));
  cam.cam_from_world = geometry::Rigid3d::LookAt(eye, Eigen::Vector3d(rng.Uniform(-3, 3), 0, 0));
  cam.has_pose = true;
  return cam;
}

Eigen::Vector3d RandomPointInView(util::Rng& rng, const Camera& cam) {
  // A point on the ray through a random pixel inside the central 90 % of the image.
  while (true) {
    const Eigen::Vector2d uv(rng.Uniform(0.05, 0.95) * cam.width,
                             rng.Uniform(0.05, 0.95) * cam.height);
    const auto ray = cam.RayFromPixel(uv);
    if (ray) return ray->At(rng.Uniform(2, 40));
  }
}

class CameraModel : public ::testing::TestWithParam<int> {};

TEST_P(CameraModel, AgreesWithOpenCvProjectPoints) {
  testing::SeededRng rng(100 + GetParam());
  for (int trial = 0; trial < 20; ++trial) {
    const Camera cam = RandomCamera(rng, GetParam());
    std::vector<cv::Point3d> pts;
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d p(rng.Uniform(-9, 9), rng.Uniform(-6, 6), rng.Uniform(0, 3));
      if ((cam.cam_from_world * p).z() > 0.5) pts.emplace_back(p.x(), p.y(), p.z());
    }
    // K and the distortion row as opencv_camera.h gives them to OpenCV.
    const cv::Mat k(IntrinsicMatrix(cam));
    const Eigen::Vector3d r = cam.cam_from_world.Rvec();
    const Eigen::Vector3d& t = cam.cam_from_world.translation;
    std::vector<cv::Point2d> uv_cv;
    cv::projectPoints(pts, cv::Vec3d(r.x(), r.y(), r.z()), cv::Vec3d(t.x(), t.y(), t.z()), k,
                      DistortionRow(cam), uv_cv);
    for (size_t i = 0; i < pts.size(); ++i) {
      // Far outside the image the high-order terms blow up; compare where pixels exist.
      if (!cam.InImage({uv_cv[i].x, uv_cv[i].y}, -0.5 * cam.width)) continue;
      const auto uv = cam.Project({pts[i].x, pts[i].y, pts[i].z});
      ASSERT_TRUE(uv);
      EXPECT_NEAR(uv->x(), uv_cv[i].x, 1e-9);
      EXPECT_NEAR(uv->y(), uv_cv[i].y, 1e-9);
    }
  }
}

TEST_P(CameraModel, ProjectUnprojectRoundTrip) {
  testing::SeededRng rng(200 + GetParam());
  for (int trial = 0; trial < 20; ++trial) {
    const Camera cam = RandomCamera(rng, GetParam());
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d p = RandomPointInView(rng, cam);
      const auto uv = cam.Project(p);
      ASSERT_TRUE(uv);
      const auto ray = cam.RayFromPixel(*uv);
      ASSERT_TRUE(ray);
      // Distance from the point to the ray, and re-projection of the ray's point.
      const Eigen::Vector3d v = p - ray->origin;
      EXPECT_LT((v - v.dot(ray->direction) * ray->direction).norm(), 1e-9);
      const auto uv2 = cam.Project(ray->At(v.norm()));
      ASSERT_TRUE(uv2);
      EXPECT_LT((*uv2 - *uv).norm(), 1e-9);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllDistortionSizes, CameraModel, ::testing::Values(0, 4, 5, 8, 12, 14));

// A strong barrel distortion (k1 -0.25) turns back at r = 1 / sqrt(0.75) = 1.155 (where the
// distorted radius peaks at 0.770): a pixel at distorted radius 0.75 has two preimages, 1 and
// 1.303; the ray is the one connected to the image's centre, and a pixel beyond the peak has
// none. Newton's method from the pixel could land on the far one: for the 12-coefficient camera
// below (one of the round trip's random cameras) it gave a ray 79 deg off the axis (normalised
// (-4.40, 2.82), where the model is folded); the pixel lies beyond that model's peak.
TEST(Camera, UndistortStaysOnTheBranchThroughTheCentre) {
  {
    Camera cam = Camera::FromFov(1280, 960, 90);
    cam.fx = 729.6781432506026;
    cam.fy = 722.4210567331595;
    cam.cx = 622.89279071187093;
    cam.cy = 471.30587631310385;
    cam.distortion = {-0.24858846113007455,    -0.02583699382378768,    -0.00019671785743719319,
                      -0.00082499718299071931, -9.7335114067485101e-05, -0.045165388743522751,
                      0.0036078457606962076,   -0.0086195111181916178,  0.00069287531997788959,
                      -8.4992185130459969e-06, -0.00043665201162106787, -2.9024374990691045e-05};
    const auto x = cam.Undistort({94.216761322540378, 773.53222470884282});
    EXPECT_TRUE(!x || x->norm() < 1.5) << x->transpose();
  }
  Camera cam = Camera::FromFov(1280, 960, 90);
  cam.distortion = {-0.25, 0, 0, 0, 0};
  for (const double angle : {0.0, 0.7, 2.0, 3.5}) {
    const Eigen::Vector2d dir(std::cos(angle), std::sin(angle));
    const Eigen::Vector2d uv(cam.cx + 0.75 * dir.x() * cam.fx, cam.cy + 0.75 * dir.y() * cam.fy);
    const auto x = cam.Undistort(uv);
    ASSERT_TRUE(x) << angle;
    EXPECT_NEAR(x->norm(), 1.0, 1e-9) << angle;  // r (1 - 0.25 r^2) = 0.75, the smaller root
    const auto back = cam.ProjectFromCamera(Eigen::Vector3d(x->x(), x->y(), 1.0));
    ASSERT_TRUE(back);
    EXPECT_LT((*back - uv).norm(), 1e-6);
    const Eigen::Vector2d beyond(cam.cx + 0.8 * dir.x() * cam.fx, cam.cy + 0.8 * dir.y() * cam.fy);
    EXPECT_FALSE(cam.Undistort(beyond)) << angle;
  }
}

// k1 alone: at radius r the image is stretched 1 + k1 r^2 across the radius and 1 + 3 k1 r^2
// along it (d/dr of r (1 + k1 r^2)); a barrel lens (k1 < 0) shrinks most along the radius.
TEST(Camera, DistortionMinScale) {
  Camera cam = Camera::FromFov(1000, 800, 90);
  EXPECT_DOUBLE_EQ(cam.DistortionMinScale({0.6, -0.3}), 1.0);
  cam.distortion = {-0.2, 0, 0, 0, 0};
  const Eigen::Vector2d xn(0.6, -0.3);
  const double r2 = xn.squaredNorm();
  EXPECT_NEAR(cam.DistortionMinScale(xn), 1 - 3 * 0.2 * r2, 1e-12);
  EXPECT_NEAR(cam.DistortionMinScale({0, 0}), 1.0, 1e-12);
  cam.distortion = {0.2, 0, 0, 0, 0};  // pincushion: the tangential stretch is the smaller one
  EXPECT_NEAR(cam.DistortionMinScale(xn), 1 + 0.2 * r2, 1e-12);
  // Beyond the fold of a strong barrel lens (1 + 3 k1 r^2 < 0): no scale.
  cam.distortion = {-0.5, 0, 0, 0, 0};
  EXPECT_FALSE(std::isfinite(cam.DistortionMinScale({1.0, 0.5})));
}

TEST(Camera, BehindAndFootprint) {
  Camera cam = Camera::FromFov(1000, 800, 90);
  cam.has_pose = true;  // identity pose: looking along +z
  EXPECT_FALSE(cam.Project({0, 0, -1}));
  EXPECT_TRUE(cam.Project({0, 0, 1}));
  EXPECT_NEAR(cam.PixelFootprintM({0, 0, 10}), 10.0 / 500.0, 1e-12);
  EXPECT_TRUE(cam.InImage({-0.4, 0}));
  EXPECT_FALSE(cam.InImage({999.6, 0}));
  // The optical axis points from the camera at what it looks at.
  EXPECT_TRUE(cam.AxisInWorld().isApprox(Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d eye(3, -4, 5), target(0, 1, 0);
  cam.cam_from_world = geometry::Rigid3d::LookAt(eye, target);
  EXPECT_TRUE(cam.AxisInWorld().isApprox((target - eye).normalized(), 1e-12));
}

TEST(CameraIo, YamlRoundTrip) {
  util::Rng rng(testing::TestSeed(3));
  Camera cam = RandomCamera(rng, 8);
  cam.name = "cam1";
  cam.rms_px = 0.25;
  cam.notes["board"] = "chessboard 9x6";
  const std::string path = testing::TempDir() + "/cam.yaml";
  WriteCameraYaml(cam, path);
  const Camera back = ReadCameraYaml(path);
  EXPECT_EQ(back.name, "cam1");
  EXPECT_EQ(back.width, 1280);
  EXPECT_DOUBLE_EQ(back.fx, cam.fx);
  EXPECT_EQ(back.distortion, cam.distortion);
  ASSERT_TRUE(back.has_pose);
  EXPECT_LT((back.cam_from_world.translation - cam.cam_from_world.translation).norm(), 1e-12);
  EXPECT_LT(
      geometry::RotationAngleBetween(back.cam_from_world.rotation, cam.cam_from_world.rotation),
      1e-12);
  ASSERT_TRUE(back.rms_px);
  EXPECT_DOUBLE_EQ(*back.rms_px, 0.25);
  EXPECT_EQ(back.notes.at("board"), "chessboard 9x6");
  // And it is readable by cv::FileStorage with the contract's keys.
  cv::FileStorage fs(path, cv::FileStorage::READ);
  cv::Mat k, rvec;
  fs["camera_matrix"] >> k;
  fs["rvec"] >> rvec;
  EXPECT_EQ(k.rows, 3);
  EXPECT_EQ(rvec.total(), 3u);
  // Saved again by an editor that puts a UTF-8 byte-order mark first (Windows Notepad).
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  std::ofstream(path, std::ios::binary) << "\xEF\xBB\xBF" << text.str();
  EXPECT_DOUBLE_EQ(ReadCameraYaml(path).fx, cam.fx);
}

TEST(CameraIo, ReadsOpenCvSampleCalibration) {
  const std::string data = testing::SharedDataDir();
  if (data.empty()) GTEST_SKIP() << "../shared/data not present";
  const Camera cam = ReadCameraYaml(data + "/opencv-chessboard/left_intrinsics.yml");
  EXPECT_EQ(cam.width, 640);
  EXPECT_NEAR(cam.fx, 535.9, 0.1);
  EXPECT_EQ(cam.distortion.size(), 5u);
  EXPECT_FALSE(cam.has_pose);
}

struct BadFile {
  const char* what;
  const char* text;
  const char* expect;  // a word the message must contain
};

class CameraIoBad : public ::testing::TestWithParam<BadFile> {};

TEST_P(CameraIoBad, OneLineErrorNamingFileAndKey) {
  const std::string path = testing::TempDir() + "/bad.yaml";
  std::ofstream(path) << GetParam().text;
  try {
    ReadCameraYaml(path);
    FAIL() << "no error for " << GetParam().what;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(GetParam().expect), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

#define FV_HDR "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
#define FV_K                                                                                      \
  "camera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: [500, 0, 320, 0, 500, " \
  "240, 0, 0, 1]\n"
#define FV_D                                                                                       \
  "distortion_coefficients: !!opencv-matrix\n  rows: 1\n  cols: 5\n  dt: d\n  data: [0, 0, 0, 0, " \
  "0]\n"

std::string BadFileName(const ::testing::TestParamInfo<BadFile>& info) {
  std::string s = info.param.what;
  for (char& c : s) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return s;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CameraIoBad,
    ::testing::Values(
        BadFile{"missing width", "%YAML:1.0\n---\nimage_height: 480\n" FV_K FV_D, "image_width"},
        BadFile{"missing matrix", FV_HDR FV_D, "camera_matrix"},
        BadFile{"missing distortion", FV_HDR FV_K, "distortion_coefficients"},
        BadFile{"2x2 matrix",
                FV_HDR "camera_matrix: !!opencv-matrix\n  rows: 2\n  cols: 2\n  dt: d\n  data: [1, "
                       "0, 0, 1]\n" FV_D,
                "3x3"},
        BadFile{"NaN focal",
                FV_HDR "camera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: "
                       "[.nan, 0, 320, 0, 500, 240, 0, 0, 1]\n" FV_D,
                "NaN"},
        BadFile{"negative focal",
                FV_HDR "camera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: "
                       "[-500, 0, 320, 0, 500, 240, 0, 0, 1]\n" FV_D,
                "focal"},
        BadFile{"6 distortion values",
                FV_HDR FV_K "distortion_coefficients: !!opencv-matrix\n  rows: 1\n  cols: 6\n  "
                            "dt: d\n  data: [0, 0, 0, 0, 0, 0]\n",
                "distortion_coefficients"},
        BadFile{"inf in tvec",
                FV_HDR FV_K FV_D "rvec: !!opencv-matrix\n  rows: 3\n  cols: 1\n  dt: d\n  data: "
                                 "[0, 0, 0]\ntvec: !!opencv-matrix\n  rows: 3\n  cols: 1\n  dt: "
                                 "d\n  data: [0, .inf, 0]\n",
                "tvec"},
        BadFile{"rvec without tvec",
                FV_HDR FV_K FV_D "rvec: !!opencv-matrix\n  rows: 3\n  cols: 1\n  dt: d\n  data: "
                                 "[0, 0, 0]\n",
                "tvec"},
        BadFile{"zero width", "%YAML:1.0\n---\nimage_width: 0\nimage_height: 480\n" FV_K FV_D,
                "image_width"},
        BadFile{"not yaml", "this is { not yaml", "bad.yaml"}, BadFile{"empty", "", "bad.yaml"},
        // Found by fuzz/camera_yaml_fuzz: OpenCV asserted (cv::Exception) on a top-level list,
        // and allocated rows x cols (80 GB) before reading a matrix's data.
        BadFile{"matrix rows not a number",
                FV_HDR FV_K "distortion_coefficients: !!opencv-matrix\n  rows: q\n  cols: 5\n  "
                            "dt: d\n  data: [0, 0, 0, 0, 0]\n",
                "distortion_coefficients"},
        BadFile{"huge matrix",
                FV_HDR FV_K "distortion_coefficients: !!opencv-matrix\n  rows: 100000\n  cols: "
                            "100000\n  dt: d\n  data: [0, 0, 0, 0, 0]\n",
                "distortion_coefficients"},
        BadFile{"top level list", "%YAML:1.0\n- 1\n- 2\n", "bad.yaml"},
        BadFile{"2e9 wide",
                "%YAML:1.0\n---\nimage_width: 2000000000\nimage_height: 480\n" FV_K FV_D,
                "image size"},
        BadFile{"1e300 focal",
                FV_HDR "camera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: "
                       "[1e300, 0, 320, 0, 500, 240, 0, 0, 1]\n" FV_D,
                "fx"},
        BadFile{"1e300 in tvec",
                FV_HDR FV_K FV_D "rvec: !!opencv-matrix\n  rows: 3\n  cols: 1\n  dt: d\n  data: "
                                 "[0, 0, 0]\ntvec: !!opencv-matrix\n  rows: 3\n  cols: 1\n  dt: "
                                 "d\n  data: [0, 1e300, 0]\n",
                "tvec"},
        // Found by fuzz/camera_yaml_fuzz: OpenCV 4.6's parser never returned (a CPU-bound hang).
        BadFile{"content after the document start", "%YAML:1.0\n--- A: 1\nna\n--m", "line 2"}),
    BadFileName);

// A camera file that cannot be written (its name is a folder) fails naming it and leaves no
// temporary file beside it (calibrate import --tsai --out FOLDER left FOLDER.tmp.yaml).
TEST(CameraIo, AFailedWriteLeavesNothingBehind) {
  const std::string dir = testing::TempDir() + "/failed_write";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir + "/cam.yaml");
  Camera cam = Camera::FromFov(64, 48, 60);
  const std::string message = testing::ErrorOf([&] { WriteCameraYaml(cam, dir + "/cam.yaml"); });
  EXPECT_THAT(message, ::testing::HasSubstr("camera file"));
  EXPECT_THAT(message, ::testing::HasSubstr("cam.yaml"));
  int entries = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) entries += !e.path().empty();
  EXPECT_EQ(entries, 1);  // the folder only
}

TEST(CameraIo, MissingFile) {
  EXPECT_THAT([&] { ReadCameraYaml("/nonexistent/cam.yaml"); },
              ThrowsMessage<Error>(HasSubstr("/nonexistent/cam.yaml")));
  const std::string folder = fv::testing::TempDir() + "/rig.yaml";
  std::filesystem::create_directories(folder);
  EXPECT_THAT([&] { ReadCameraYaml(folder); }, ThrowsMessage<Error>(HasSubstr("is a folder")));
}

}  // namespace
}  // namespace fv::camera
