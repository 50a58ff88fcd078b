// The camera stage's tracking window: a ball that leaves the window where another accepted object
// lies is found again by a whole-frame search in that frame, not after full_scan_every frames.
#include "fieldvision/pipeline/camera_stage.h"

#include <gtest/gtest.h>

namespace fv::pipeline {
namespace {

using Eigen::Vector2d;

struct Thing {
  Vector2d centre_px;
  double score;
};

// A scripted detector: the things of frame `f` that lie inside the searched region.
BallRegionDetectFn Scripted(const std::vector<std::vector<Thing>>* frames, const long long* f) {
  return [frames, f](const cv::Mat&, const cv::Rect& roi) {
    std::vector<recon::BallObservation> out;
    for (const Thing& t : (*frames)[*f]) {
      if (!roi.empty() && !roi.contains(cv::Point(static_cast<int>(t.centre_px.x()),
                                                  static_cast<int>(t.centre_px.y())))) {
        continue;
      }
      recon::BallObservation o;
      o.centre_px = t.centre_px;
      o.radius_px = 5.0;
      o.score = t.score;
      out.push_back(o);
    }
    return out;
  };
}

TEST(CameraStage, ABallThatLeavesItsWindowIsSearchedForInTheWholeFrame) {
  const camera::Camera cam = camera::Camera::FromFov(640, 480, 60.0);
  // The ball rolls right at 10 px a frame, then bounces up at 40 px a frame: out of the window
  // around where it was expected. A static object (a cone, score lower) lies inside that window,
  // 25 px from where the ball was expected.
  std::vector<std::vector<Thing>> frames;
  const Vector2d cone(200, 265);
  Vector2d ball(100, 240);
  for (int f = 0; f < 16; ++f) {
    ball += f < 10 ? Vector2d(10, 0) : Vector2d(0, -12);
    if (f == 10) ball += Vector2d(-10, -48);
    frames.push_back({{ball, 0.9}, {cone, 0.5}});
  }
  long long f = 0;
  BallTrackOptions track;
  track.full_scan_every = 100;
  CameraStage stage(0, cam, Scripted(&frames, &f), track, "scripted");
  for (f = 0; f < static_cast<long long>(frames.size()); ++f) {
    io::SourceFrame in;
    in.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0));
    in.frame = f;
    const CameraMessage m = stage.Process(in);
    const Vector2d& want = frames[f][0].centre_px;
    const bool has_ball = std::any_of(m.candidates.begin(), m.candidates.end(), [&](const auto& o) {
      return (o.centre_px - want).norm() < 1;
    });
    EXPECT_TRUE(has_ball) << "frame " << f << ": the ball at (" << want.transpose()
                          << ") is not among the " << m.candidates.size() << " candidates";
  }
  EXPECT_LT(stage.stats().full_scans, 4);  // the first frame, and where the ball jumped
}

}  // namespace
}  // namespace fv::pipeline
