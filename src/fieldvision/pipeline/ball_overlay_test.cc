#include "fieldvision/pipeline/ball_overlay.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::pipeline {
namespace {

namespace fs = std::filesystem;

// Two posed cameras, five grey frames each, the ball at a known place in frames 1-3 and one
// camera's candidate there: each camera's video shows the ball (cyan) where it projects, the
// candidate (green) in the camera that has it, and as many frames as its input.
TEST(BallOverlay, DrawsTheBallWhereEachCameraSeesIt) {
  const std::string dir = fv::testing::TempDir() + "/ball_overlay";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::vector<camera::Camera> cams;
  std::vector<std::string> videos;
  const Eigen::Vector3d eyes[] = {{-6, -4, 3}, {6, -4, 3}};
  const Eigen::Vector3d ball(0.5, 0.3, 0.11);
  for (int c = 0; c < 2; ++c) {
    camera::Camera cam = camera::Camera::FromFov(320, 240, 50);
    cam.name = fmt::format("cam{}", c + 1);
    cam.has_pose = true;
    cam.cam_from_world = geometry::Rigid3d::LookAt(eyes[c], Eigen::Vector3d(0, 0, 0));
    cams.push_back(cam);
    fs::create_directories(fmt::format("{}/{}", dir, cam.name));
    for (int f = 0; f < 5; ++f) {
      cv::imwrite(fmt::format("{}/{}/{:05d}.png", dir, cam.name, f),
                  cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(90)));
    }
    videos.push_back(fmt::format("{}/{}/%05d.png", dir, cam.name));
  }
  {
    std::ofstream csv(dir + "/ball.csv");
    csv << "frame,time_s,x_m,y_m,z_m,n_cams,err_px\n";
    for (int f = 1; f <= 3; ++f) {
      csv << fmt::format("{},{},{},{},{},2,0.1\n", f, f / 30.0, ball.x(), ball.y(), ball.z());
    }
  }
  const Eigen::Vector2d seen = *cams[0].Project(ball);
  {
    std::ofstream det(dir + "/cam1_det.csv");
    det << "frame,time_s,u,v,radius_px,score\n";
    det << fmt::format("2,{},{},{},3,0.9\n", 2 / 30.0, seen.x() + 20, seen.y());
  }
  std::ofstream(dir + "/cam2_det.csv") << "frame,time_s,u,v,radius_px,score\n";
  BallOverlayOptions o;
  o.dir = dir + "/drawn";
  o.progress = false;
  fs::create_directories(o.dir);
  const BallOverlayResult r = DrawBallOverlays(cams, videos, dir + "/ball.csv",
                                               {dir + "/cam1_det.csv", dir + "/cam2_det.csv"}, o);
  EXPECT_EQ(r.frames, 10) << r.Summary();
  EXPECT_EQ(r.balls_drawn, 6) << r.Summary();
  ASSERT_EQ(r.videos.size(), 2u);
  const auto frame_of = [](const std::string& path, int index) {
    cv::VideoCapture in(path);
    cv::Mat f;
    for (int i = 0; i <= index; ++i) in.read(f);
    return f;
  };
  const auto colour_near = [](const cv::Mat& img, const Eigen::Vector2d& p, int reach,
                              const cv::Vec3b& colour) {
    int n = 0;
    for (int y = static_cast<int>(p.y()) - reach; y <= static_cast<int>(p.y()) + reach; ++y) {
      for (int x = static_cast<int>(p.x()) - reach; x <= static_cast<int>(p.x()) + reach; ++x) {
        if (x < 0 || y < 0 || x >= img.cols || y >= img.rows) continue;
        const cv::Vec3b& q = img.at<cv::Vec3b>(y, x);
        n += std::abs(q[0] - colour[0]) + std::abs(q[1] - colour[1]) + std::abs(q[2] - colour[2]) <
             150;
      }
    }
    return n;
  };
  const cv::Vec3b cyan(255, 255, 0), green(0, 255, 0);
  // A cyan tint on the grey frame (the video's compression spreads a 1-px line's colour).
  const auto tinted = [](const cv::Mat& img, const Eigen::Vector2d& p, int reach) {
    int n = 0;
    for (int y = cvRound(p.y()) - reach; y <= cvRound(p.y()) + reach; ++y) {
      for (int x = cvRound(p.x()) - reach; x <= cvRound(p.x()) + reach; ++x) {
        if (x < 0 || y < 0 || x >= img.cols || y >= img.rows) continue;
        const cv::Vec3b& q = img.at<cv::Vec3b>(y, x);
        n += std::min(q[0], q[1]) - q[2] > 30;
      }
    }
    return n;
  };
  for (int c = 0; c < 2; ++c) {
    const cv::Mat f0 = frame_of(r.videos[c], 0), f2 = frame_of(r.videos[c], 2);
    ASSERT_FALSE(f2.empty()) << r.videos[c];
    EXPECT_GT(f2.rows, 240) << "a legend below the frame";
    const Eigen::Vector2d uv = *cams[c].Project(ball);
    EXPECT_EQ(colour_near(f0, uv, 12, cyan), 0) << "no ball in frame 0, camera " << c;
    // The outline at the ball's projected size: on the diagonals (where the ticks are not), cyan
    // at that radius and none 3 px farther out.
    const double r_px = 0.11 * cams[c].fx / (cams[c].cam_from_world * ball).z();
    for (const Eigen::Vector2d& d : {Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1),
                                     Eigen::Vector2d(1, -1), Eigen::Vector2d(-1, -1)}) {
      const Eigen::Vector2d unit = d.normalized();
      EXPECT_GT(tinted(f2, uv + r_px * unit, 1), 0) << "camera " << c << " r " << r_px;
      EXPECT_EQ(tinted(f2, uv + (r_px + 3) * unit, 0), 0) << "camera " << c;
    }
  }
  EXPECT_GT(colour_near(frame_of(r.videos[0], 2), seen + Eigen::Vector2d(20, 0), 5, green), 3);
  EXPECT_EQ(colour_near(frame_of(r.videos[1], 2), *cams[1].Project(ball) + Eigen::Vector2d(20, 0),
                        5, green),
            0);
  // The sequences' rate: 30 stands in; `ball --fps` gives theirs.
  EXPECT_NEAR(cv::VideoCapture(r.videos[0]).get(cv::CAP_PROP_FPS), 30.0, 0.01);
  BallOverlayOptions at60 = o;
  at60.dir = dir + "/drawn60";
  at60.fps = 60;
  fs::create_directories(at60.dir);
  const BallOverlayResult r60 = DrawBallOverlays(cams, videos, dir + "/ball.csv", {}, at60);
  ASSERT_EQ(r60.videos.size(), 2u);
  EXPECT_NEAR(cv::VideoCapture(r60.videos[1]).get(cv::CAP_PROP_FPS), 60.0, 0.01);
  // A camera without its video, or BALL.csv missing: one error naming it.
  EXPECT_THROW(DrawBallOverlays(cams, {videos[0]}, dir + "/ball.csv", {}, o), Error);
  try {
    DrawBallOverlays(cams, videos, dir + "/missing.csv", {}, o);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.csv"), std::string::npos) << e.what();
  }
}

// Video file names from camera names: safe characters only, never a path, each name once.
TEST(BallOverlay, DrawNamesAreSafeAndUnique) {
  EXPECT_EQ(
      DrawNames({"cam1", "cam1", "cam1-2", "../x", "a/b", "", ".hidden"}),
      (std::vector<std::string>{"cam1", "cam1-2", "cam1-2-2", "___x", "a_b", "cam6", "_hidden"}));
}

}  // namespace
}  // namespace fv::pipeline
