#include "fieldvision/calib/board.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/calib/intrinsics.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::calib {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

constexpr double kBoardPxPerM = 4000.0;  // resolution of the flat board picture

// A flat picture of the board; pixel (x, y) is the board point (x, y) / kBoardPxPerM - origin.
cv::Mat BoardPicture(const BoardSpec& b, cv::Point2d* origin_m) {
  if (b.type == BoardType::kChessboard) {
    const int sq = static_cast<int>(b.square_m * kBoardPxPerM);
    const int margin = sq;
    cv::Mat img((b.rows + 1) * sq + 2 * margin, (b.cols + 1) * sq + 2 * margin, CV_8U,
                cv::Scalar(255));
    for (int r = 0; r <= b.rows; ++r) {
      for (int c = 0; c <= b.cols; ++c) {
        if ((r + c) % 2 == 0) {
          img(cv::Rect(margin + c * sq, margin + r * sq, sq, sq)).setTo(0);
        }
      }
    }
    // Inner corner (0, 0) is one square in from the board's corner.
    *origin_m = cv::Point2d((margin + sq) / kBoardPxPerM, (margin + sq) / kBoardPxPerM);
    return img;
  }
  const auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
  const auto board = cv::aruco::CharucoBoard::create(
      b.cols, b.rows, b.square_m, b.marker_m > 0 ? b.marker_m : 0.7 * b.square_m, dict);
  cv::Mat img;
  const int margin = static_cast<int>(b.square_m * kBoardPxPerM / 2);
  board->draw(cv::Size(static_cast<int>(b.cols * b.square_m * kBoardPxPerM) + 2 * margin,
                       static_cast<int>(b.rows * b.square_m * kBoardPxPerM) + 2 * margin),
              img, margin, 1);
  // OpenCV's ChArUco corners are measured from the board's top-left corner.
  *origin_m = cv::Point2d(margin / kBoardPxPerM, margin / kBoardPxPerM);
  return img;
}

// The board seen by a pinhole camera (no distortion) at pose (rvec, tvec).
cv::Mat RenderView(const cv::Mat& picture, const cv::Point2d& origin_m, const cv::Matx33d& k,
                   const cv::Vec3d& rvec, const cv::Vec3d& tvec, cv::Size size) {
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  // Board picture pixel -> board metres -> image: H = K [r1 r2 t] S.
  const cv::Matx33d rt(r(0, 0), r(0, 1), tvec[0], r(1, 0), r(1, 1), tvec[1], r(2, 0), r(2, 1),
                       tvec[2]);
  const cv::Matx33d s(1 / kBoardPxPerM, 0, -origin_m.x, 0, 1 / kBoardPxPerM, -origin_m.y, 0, 0, 1);
  const cv::Matx33d h = k * rt * s;
  cv::Mat out;
  cv::warpPerspective(picture, out, h, size, cv::INTER_AREA, cv::BORDER_CONSTANT, cv::Scalar(150));
  cv::GaussianBlur(out, out, cv::Size(3, 3), 0.6);
  return out;
}

// Views of the board from random tilts and positions; writes them into `dir`. Returns how many
// show the whole board, its white border included, inside the image.
int WriteViews(const BoardSpec& b, const cv::Matx33d& k, cv::Size size, int n, util::Rng& rng,
               const std::string& dir, double distance_m) {
  cv::Point2d origin;
  const cv::Mat picture = BoardPicture(b, &origin);
  const double w = b.cols * b.square_m, h = b.rows * b.square_m;
  // The picture's corners in board metres (inner corner (0, 0) at the origin).
  const double pw = picture.cols / kBoardPxPerM, ph = picture.rows / kBoardPxPerM;
  const std::vector<cv::Point3d> outline = {{-origin.x, -origin.y, 0},
                                            {pw - origin.x, -origin.y, 0},
                                            {pw - origin.x, ph - origin.y, 0},
                                            {-origin.x, ph - origin.y, 0}};
  int whole = 0;
  for (int i = 0; i < n; ++i) {
    const cv::Vec3d rvec(rng.Uniform(-0.5, 0.5), rng.Uniform(-0.5, 0.5), rng.Uniform(-0.3, 0.3));
    const cv::Vec3d tvec(-0.5 * w + rng.Uniform(-0.25, 0.25) * distance_m,
                         -0.5 * h + rng.Uniform(-0.18, 0.18) * distance_m,
                         distance_m * rng.Uniform(0.9, 1.2));
    cv::imwrite(fmt::format("{}/view{:02d}.png", dir, i),
                RenderView(picture, origin, k, rvec, tvec, size));
    std::vector<cv::Point2d> uv;
    cv::projectPoints(outline, rvec, tvec, k, cv::noArray(), uv);
    whole += std::all_of(uv.begin(), uv.end(), [&](const cv::Point2d& p) {
      return p.x >= 0 && p.y >= 0 && p.x < size.width && p.y < size.height;
    });
  }
  return whole;
}

TEST(Board, SyntheticChessboardViewsRecoverTheFocalLength) {
  fv::testing::SeededRng rng(21);
  const cv::Size size(640, 480);
  const cv::Matx33d k(600, 0, 322, 0, 600, 236, 0, 0, 1);
  IntrinsicsOptions o;
  o.board = {BoardType::kChessboard, 7, 5, 0.03};
  o.progress = false;
  o.num_distortion = 4;
  const std::string dir = fv::testing::TempDir();
  const int whole = WriteViews(o.board, k, size, 10, rng, dir, 0.45);
  const IntrinsicsResult r = CalibrateIntrinsics(dir, o);
  // Every view with the whole board in the image is used (7-10 of the 10 over seeds 1-30).
  EXPECT_GE(r.num_used, whole) << r.Summary();
  EXPECT_GE(r.num_used, 6) << r.Summary();
  // Within 6 px or its own 3 standard deviations (seed 59: 6 views, 6.7 px off, std 7.5 px).
  EXPECT_NEAR(r.camera.fx, 600, std::max(6.0, 3 * r.std_fx_px)) << r.Summary();
  EXPECT_NEAR(r.camera.fy, 600, std::max(6.0, 3 * r.std_fy_px)) << r.Summary();
  EXPECT_NEAR(r.camera.cx, 322, 8) << r.Summary();
  EXPECT_NEAR(r.camera.cy, 236, 8) << r.Summary();
  EXPECT_LT(r.rms_px, 0.5);
  EXPECT_EQ(r.camera.distortion.size(), 4u);
}

// Every model the options list fits (OpenCV refused the thin-prism model of 12 numbers when
// started from 14).
TEST(Board, EveryDistortionModelFits) {
  fv::testing::SeededRng rng(23);
  const cv::Size size(640, 480);
  const cv::Matx33d k(600, 0, 322, 0, 600, 236, 0, 0, 1);
  IntrinsicsOptions o;
  o.board = {BoardType::kChessboard, 7, 5, 0.03};
  o.progress = false;
  const std::string dir = fv::testing::TempDir();
  WriteViews(o.board, k, size, 10, rng, dir, 0.45);
  for (const int model : {4, 5, 8, 12, 14}) {
    o.num_distortion = model;
    const IntrinsicsResult r = CalibrateIntrinsics(dir, o);
    EXPECT_EQ(r.camera.distortion.size(), static_cast<size_t>(model));
    EXPECT_LT(r.rms_px, 0.5) << "model " << model << ": " << r.Summary();
  }
}

TEST(Board, ChArUcoPartialViewsCount) {
  fv::testing::SeededRng rng(22);
  const cv::Size size(640, 480);
  const cv::Matx33d k(580, 0, 318, 0, 580, 242, 0, 0, 1);
  BoardSpec b{BoardType::kCharuco, 7, 5, 0.04, 0.03, "DICT_4X4_50"};
  cv::Point2d origin;
  const cv::Mat picture = BoardPicture(b, &origin);
  DetectOptions d;
  // A view with the board cut by the image's right edge still gives corners.
  const cv::Mat partial =
      RenderView(picture, origin, k, cv::Vec3d(0.1, 0.2, 0.0), cv::Vec3d(0.05, -0.1, 0.5), size);
  const BoardView v = DetectBoard(partial, b, d, "partial");
  const int all = (b.cols - 1) * (b.rows - 1);
  EXPECT_GE(static_cast<int>(v.image_points.size()), 6);
  EXPECT_LT(static_cast<int>(v.image_points.size()), all);
  // Each detected corner is where the camera puts its board point.
  std::vector<cv::Point2d> proj;
  std::vector<cv::Point3d> obj(v.object_points.begin(), v.object_points.end());
  cv::projectPoints(obj, cv::Vec3d(0.1, 0.2, 0.0), cv::Vec3d(0.05, -0.1, 0.5), k, cv::noArray(),
                    proj);
  for (size_t i = 0; i < proj.size(); ++i) {
    EXPECT_LT(cv::norm(cv::Point2d(v.image_points[i]) - proj[i]), 1.5)
        << "corner " << v.corner_ids[i];
  }

  IntrinsicsOptions o;
  o.board = b;
  o.progress = false;
  o.num_distortion = 4;
  const std::string dir = fv::testing::TempDir();
  WriteViews(b, k, size, 10, rng, dir, 0.6);
  const IntrinsicsResult r = CalibrateIntrinsics(dir, o);
  EXPECT_GE(r.num_used, 8) << r.Summary();
  // Within its own uncertainty (3 standard deviations; about 6 px here at seed 8, 8.1 px off).
  EXPECT_NEAR(r.camera.fx, 580, std::max(8.0, 3 * r.std_fx_px)) << r.Summary();
  EXPECT_NEAR(r.camera.cx, 318, std::max(10.0, 3 * r.std_cx_px)) << r.Summary();
}

TEST(Board, VideoIsSampledEvenly) {
  fv::testing::SeededRng rng(23);
  const cv::Size size(640, 480);
  const cv::Matx33d k(600, 0, 322, 0, 600, 236, 0, 0, 1);
  BoardSpec b{BoardType::kChessboard, 7, 5, 0.03};
  const std::string dir = fv::testing::TempDir();
  const int whole = WriteViews(b, k, size, 12, rng, dir, 0.45);
  const std::string video = dir + "/board.avi";
  {
    cv::VideoWriter w(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, size, true);
    ASSERT_TRUE(w.isOpened());
    const ImageSource views(dir + "/view*.png");
    for (int i = 0; i < views.size(); ++i) {
      cv::Mat bgr;
      cv::cvtColor(views.Read(i), bgr, cv::COLOR_GRAY2BGR);
      for (int repeat = 0; repeat < 3; ++repeat) w.write(bgr);  // 36 frames
    }
  }
  IntrinsicsOptions o;
  o.board = b;
  o.progress = false;
  o.num_distortion = 4;
  o.source.max_video_frames = 12;
  const IntrinsicsResult r = CalibrateIntrinsics(video, o);
  EXPECT_EQ(r.num_images, 12);
  // One frame of each view: every view with the whole board in the image is used (8 of the 12
  // at seeds 59 and 70).
  EXPECT_GE(r.num_used, std::min(whole, 9)) << r.Summary();
  EXPECT_GE(r.num_used, 6) << r.Summary();
  EXPECT_NEAR(r.camera.fx, 600, 8) << r.Summary();
  EXPECT_NE(r.views[0].name.find("board.avi#"), std::string::npos) << r.views[0].name;
}

TEST(Board, NoBoardInAnyImageIsAnErrorNamingTheInput) {
  const std::string dir = fv::testing::TempDir();
  for (int i = 0; i < 3; ++i) {
    cv::imwrite(fmt::format("{}/blank{}.png", dir, i), cv::Mat(120, 160, CV_8U, cv::Scalar(90)));
  }
  IntrinsicsOptions o;
  o.board = {BoardType::kChessboard, 9, 6, 0.025};
  o.progress = false;
  EXPECT_THAT([&] { CalibrateIntrinsics(dir, o); },
              ThrowsMessage<Error>(::testing::AllOf(HasSubstr("no chessboard 9x6"), HasSubstr(dir),
                                                    HasSubstr("3 images"))));
}

TEST(Board, ImagesOfDifferentSizesAreAnError) {
  const std::string dir = fv::testing::TempDir();
  cv::imwrite(dir + "/a.png", cv::Mat(120, 160, CV_8U, cv::Scalar(90)));
  cv::imwrite(dir + "/b.png", cv::Mat(100, 160, CV_8U, cv::Scalar(90)));
  IntrinsicsOptions o;
  o.progress = false;
  EXPECT_THAT([&] { CalibrateIntrinsics(dir, o); }, ThrowsMessage<Error>(HasSubstr("b.png")));
}

TEST(Board, MissingOrEmptyInputsAreErrors) {
  const std::string dir = fv::testing::TempDir();
  EXPECT_THROW(ImageSource{dir + "/nothing-here"}, Error);
  EXPECT_THROW(ImageSource{dir}, Error);  // empty folder
  EXPECT_THROW(ImageSource{dir + "/*.jpg"}, Error);
  {
    std::ofstream f(dir + "/broken.jpg");
    f << "not a jpeg";
  }
  const ImageSource s(dir + "/broken.jpg");
  EXPECT_THROW(s.Read(0), Error);
  {
    std::ofstream f(dir + "/broken.mp4");
    f << "not a video";
  }
  EXPECT_THROW(ImageSource{dir + "/broken.mp4"}, Error);
}

TEST(Board, OptionsCheckNamesTheField) {
  BoardSpec b;
  b.square_m = -1;
  EXPECT_THAT([&] { b.Check(); }, ThrowsMessage<Error>(HasSubstr("square")));
  IntrinsicsOptions o;
  o.num_distortion = 6;
  EXPECT_THAT([&] { o.Check(); }, ThrowsMessage<Error>(HasSubstr("num_distortion")));
  EXPECT_THROW(ParseBoardType("circles"), Error);
}

}  // namespace
}  // namespace fv::calib
