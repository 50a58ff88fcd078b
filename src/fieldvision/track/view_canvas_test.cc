#include "fieldvision/track/view_canvas.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/camera/opencv_camera.h"
#include "fieldvision/track/camera_motion.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::track {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// A 640x480 barrel lens looking down at the field from the side line.
camera::Camera Lens() {
  camera::Camera cam = camera::Camera::FromFov(640, 480, 70);
  cam.distortion = {-0.25, 0.08, 0.0, 0.0, 0.0};
  cam.cam_from_world = geometry::Rigid3d::LookAt({0, -14, 8}, {0, 0, 0});
  cam.has_pose = true;
  return cam;
}

// The lens turned by `rvec` about its centre (x_cam' = Q x_cam), and the homography from its
// undistorted pixels to the unturned lens's: K Q^T K^-1.
camera::Camera Turned(const camera::Camera& lens, const cv::Vec3d& rvec, cv::Matx33d* first_from) {
  cv::Matx33d q;
  cv::Rodrigues(rvec, q);
  const cv::Matx33d k = camera::IntrinsicMatrix(lens);
  *first_from = k * q.t() * k.inv();
  camera::Camera turned = lens;
  Eigen::Matrix3d qe;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) qe(r, c) = q(r, c);
  }
  const Eigen::Vector3d centre = lens.CentreInWorld();
  turned.cam_from_world.rotation = qe * lens.cam_from_world.rotation;
  turned.cam_from_world.translation = -(turned.cam_from_world.rotation * centre);
  return turned;
}

// Field points seen by a turned camera land on the canvas where the first view's camera (the
// canvas's, pinhole) puts them, and canvas points go back to the turned camera's pixels: within
// 1e-3 px for turns of up to 0.5 rad and a strong barrel lens (seeds 1-50). A box moved there
// and back is the same box within 0.01 px (the lens's inversion converges to about 1e-3 px).
TEST(ViewCanvas, TurnedCameraPointsLandWhereTheFirstViewSeesThem) {
  testing::SeededRng rng(4);
  const camera::Camera lens = Lens();
  ViewCanvas canvas(lens, 1.0);
  EXPECT_EQ(canvas.size(), cv::Size(3 * 640, 3 * 480));
  EXPECT_TRUE(canvas.camera().distortion.empty());
  canvas.AddFrame(cv::Matx33d::eye());
  cv::Matx33d first_from;
  const camera::Camera turned =
      Turned(lens, {rng.Uniform(-0.1, 0.1), rng.Uniform(-0.5, 0.5), rng.Uniform(-0.05, 0.05)},
             &first_from);
  canvas.AddFrame(first_from);
  int seen = 0;
  for (double x = -30; x <= 30; x += 3) {
    for (double y = -20; y <= 20; y += 2.5) {
      const Eigen::Vector3d p(x, y, 0);
      const auto in_frame = turned.Project(p);
      const auto on_canvas = canvas.camera().Project(p);
      if (!in_frame || !on_canvas || !turned.InImage(*in_frame)) continue;
      ++seen;
      const auto mapped = canvas.ToCanvas(1, {in_frame->x(), in_frame->y()});
      ASSERT_TRUE(mapped.has_value());
      EXPECT_NEAR(mapped->x, on_canvas->x(), 1e-3) << x << "," << y;
      EXPECT_NEAR(mapped->y, on_canvas->y(), 1e-3) << x << "," << y;
      const auto back = canvas.ToFrame(1, *mapped);
      ASSERT_TRUE(back.has_value());
      EXPECT_NEAR(back->x, in_frame->x(), 1e-3);
      EXPECT_NEAR(back->y, in_frame->y(), 1e-3);
    }
  }
  EXPECT_GT(seen, 50);
  const cv::Rect2d box(300, 200, 30, 90);
  const cv::Rect2d there_and_back = canvas.BoxToFrame(1, canvas.BoxToCanvas(1, box));
  EXPECT_NEAR(there_and_back.x, box.x, 0.01);
  EXPECT_NEAR(there_and_back.y, box.y, 0.01);
  EXPECT_NEAR(there_and_back.width, box.width, 0.01);
  EXPECT_NEAR(there_and_back.height, box.height, 0.01);
}

// A turned frame drawn on the canvas: each canvas pixel shows the frame's pixel that maps there
// (a smooth pattern, within 12 levels in two channels together), the previous frame's pixels are
// cleared, and what the frame sees of the canvas is the frame again
// (mean difference under 2 levels inside). Seeds 1-50.
TEST(ViewCanvas, DrawnFrameAndWhatTheFrameSeesAgree) {
  testing::SeededRng rng(6);
  const camera::Camera lens = Lens();
  ViewCanvas canvas(lens, 1.0);
  cv::Mat frame(480, 640, CV_8UC3);
  const double fx = rng.Uniform(0.01, 0.03), fy = rng.Uniform(0.01, 0.03);
  for (int y = 0; y < frame.rows; ++y) {
    for (int x = 0; x < frame.cols; ++x) {
      frame.at<cv::Vec3b>(y, x) =
          cv::Vec3b(cv::saturate_cast<uchar>(128 + 100 * std::sin(fx * x)),
                    cv::saturate_cast<uchar>(128 + 100 * std::cos(fy * y)), 90);
    }
  }
  cv::Mat image;
  canvas.AddFrame(cv::Matx33d::eye());
  const cv::Rect first = canvas.Draw(0, frame, image);
  cv::Matx33d first_from;
  Turned(lens, {0.05, rng.Uniform(0.2, 0.4), 0.0}, &first_from);
  canvas.AddFrame(first_from);
  const cv::Rect second = canvas.Draw(1, frame, image);
  ASSERT_FALSE(second.empty());
  EXPECT_GT(std::abs(second.x - first.x), 50);  // the view moved
  for (int y = 40; y < 440; y += 37) {
    for (int x = 40; x < 600; x += 41) {
      const auto c = canvas.ToCanvas(1, {x + 0.0, y + 0.0});
      ASSERT_TRUE(c.has_value());
      const cv::Vec3b got = image.at<cv::Vec3b>(cvRound(c->y), cvRound(c->x));
      const cv::Vec3b want = frame.at<cv::Vec3b>(y, x);
      EXPECT_LE(std::abs(got[0] - want[0]) + std::abs(got[1] - want[1]), 12) << x << "," << y;
    }
  }
  // Outside the second frame's footprint the first one's pixels are gone.
  cv::Mat outside;
  cv::cvtColor(image, outside, cv::COLOR_BGR2GRAY);
  outside(second).setTo(0);
  EXPECT_EQ(cv::countNonZero(outside), 0);
  const cv::Mat seen = canvas.SeenByFrame(1, image);
  ASSERT_EQ(seen.size(), frame.size());
  const cv::Rect inner(20, 20, 600, 440);
  cv::Mat diff;
  cv::absdiff(seen(inner), frame(inner), diff);
  EXPECT_LT(cv::mean(diff)[0] + cv::mean(diff)[1], 4.0);
}

// A canvas point far beyond a strong barrel lens's fold (k1 -0.3 folds at 1.05 normalized) is not
// in the frame's view, though the lens model would put it back inside the image. A camera turned
// by 100 degrees: the ray through its centre does not meet the canvas (it points behind the first
// view), so it is not placed there, and the canvas's centre is not taken into its view.
TEST(ViewCanvas, PointsBeyondTheLensOrBehindTheViewAreNotInTheFrame) {
  camera::Camera lens = Lens();
  lens.distortion = {-0.3, 0, 0, 0, 0};
  ViewCanvas canvas(lens, 1.0);
  canvas.AddFrame(cv::Matx33d::eye());
  const double cx = canvas.camera().cx, cy = canvas.camera().cy;
  EXPECT_FALSE(canvas.ToFrame(0, {cx + 1.6 * lens.fx, cy}).has_value());
  EXPECT_TRUE(canvas.ToFrame(0, {cx + 0.5 * lens.fx, cy}).has_value());
  cv::Matx33d first_from;
  Turned(Lens(), {0.0, 100.0 * M_PI / 180.0, 0.0}, &first_from);
  ViewCanvas wide(Lens(), 1.0);
  wide.AddFrame(first_from);
  EXPECT_FALSE(wide.ToCanvas(0, {lens.cx, lens.cy}).has_value());
  EXPECT_FALSE(wide.ToFrame(0, {wide.camera().cx, wide.camera().cy}).has_value());
}

// Bad input: a margin out of range or making a canvas over 100 Mpx, a homography with NaN, a frame
// of another size, an image of another size than the canvas, a frame index beyond those added:
// each one error naming it.
TEST(ViewCanvas, BadInputIsRefused) {
  const camera::Camera lens = Lens();
  EXPECT_THAT([&] { ViewCanvas(lens, -1.0); },
              ThrowsMessage<Error>(HasSubstr("canvas margin must be in [0, 10]")));
  EXPECT_THAT([&] { ViewCanvas(lens, std::nan("")); },
              ThrowsMessage<Error>(HasSubstr("canvas margin")));
  ViewCanvas canvas(lens, 0.2);
  cv::Matx33d bad = cv::Matx33d::eye();
  bad(0, 2) = std::nan("");
  EXPECT_THAT([&] { canvas.AddFrame(bad); },
              ThrowsMessage<Error>(HasSubstr("frame 1 has no usable homography")));
  canvas.AddFrame(cv::Matx33d::eye());
  cv::Mat image;
  EXPECT_THAT([&] { canvas.Draw(0, cv::Mat(100, 100, CV_8UC3), image); },
              ThrowsMessage<Error>(HasSubstr("is not a 640x480 BGR image")));
  EXPECT_THAT([&] { canvas.SeenByFrame(0, cv::Mat(10, 10, CV_8U)); },
              ThrowsMessage<Error>(HasSubstr("the image is 10x10")));
  EXPECT_THAT([&] { canvas.ToFrame(3, {0, 0}); }, ThrowsMessage<Error>(HasSubstr("frame 3 of 1")));
  EXPECT_THAT(
      [&] {
        ViewCanvas::Uncalibrated({0, 0}, 1.0);
      },
      ThrowsMessage<Error>(HasSubstr("the frames' size")));
  EXPECT_THAT([&] { ViewCanvas(lens, 10.0); },
              ThrowsMessage<Error>(HasSubstr("13440x10080 canvas (over 100 Mpx)")));
}

}  // namespace
}  // namespace fv::track
