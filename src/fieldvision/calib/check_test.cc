#include "fieldvision/calib/check.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/synth/synth.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::calib {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(Check, TruePoseHasSmallLineErrorAndAShiftedOneLarge) {
  synth::SceneSpec spec = synth::Preset("static", fv::testing::TestSeed(41));
  spec.cameras.resize(1);
  synth::ResizeCameras(spec, 640, 480);
  spec.num_frames = 1;
  spec.ball.placements.resize(1);
  const synth::SceneRenderer scene(spec);
  const camera::Camera& truth = scene.cameras()[0];
  const cv::Mat frame = scene.Render(0)[0];
  std::vector<PointCorrespondence> known;
  for (const char* name : {"centre_spot", "corner_left_bottom", "penalty_mark_left"}) {
    const auto* k = scene.field().FindKeypoint(name);
    ASSERT_NE(k, nullptr);
    known.push_back({name, *truth.Project(k->position_m), k->position_m});
  }
  const CheckResult good = CheckCalibration(truth, frame, scene.field(), known);
  EXPECT_GT(good.lines.num_inliers, 300) << good.Summary();
  EXPECT_LT(good.lines.median_mm, 20.0) << good.Summary();
  ASSERT_EQ(good.points.size(), 3u);
  for (const auto& p : good.points) EXPECT_LT(p.err_px, 1e-6);
  EXPECT_EQ(good.overlay.size(), frame.size());
  EXPECT_GT(cv::norm(good.overlay, frame, cv::NORM_L1), 0.0);  // something was drawn

  camera::Camera shifted = truth;
  const Eigen::Vector3d centre = truth.CentreInWorld() + Eigen::Vector3d(0.3, -0.2, 0.0);
  shifted.cam_from_world.translation = -shifted.cam_from_world.rotation * centre;
  const CheckResult bad = CheckCalibration(shifted, frame, scene.field(), known);
  EXPECT_GT(bad.lines.median_mm, 3 * good.lines.median_mm) << bad.Summary();
  for (const auto& p : bad.points) EXPECT_GT(p.err_px, 1.0);

  const std::string table = fv::testing::TempDir() + "/table.csv";
  WritePointErrorTable(table, bad.points);
  const util::CsvTable t = util::CsvTable::Read(table);
  ASSERT_EQ(t.rows(), 3u);
  EXPECT_NEAR(t.GetDouble(0, "err_px"), bad.points[0].err_px, 1e-3);
}

TEST(Check, CameraWithoutPoseOrWrongSizeIsAnError) {
  camera::Camera cam = camera::Camera::FromFov(640, 480, 60);
  const cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(0, 100, 0));
  const field::FieldModel field = field::BuiltinField("robocup-msl");
  EXPECT_THROW(CheckCalibration(cam, frame, field, {}), Error);
  cam.has_pose = true;
  cam.cam_from_world =
      geometry::Rigid3d::LookAt(Eigen::Vector3d(-15, -12, 7), Eigen::Vector3d::Zero());
  const cv::Mat other(360, 640, CV_8UC3, cv::Scalar(0, 100, 0));
  EXPECT_THAT([&] { CheckCalibration(cam, other, field, {}); },
              ThrowsMessage<Error>(HasSubstr("640x360")));
}

}  // namespace
}  // namespace fv::calib
