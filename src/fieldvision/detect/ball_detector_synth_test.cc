// Ball detection on rendered scenes (fv::synth) with exact truth: sub-pixel accuracy over the
// 6-40 px diameter range, partly occluded balls, the orange cone distractor, no ball.
#include <algorithm>

#if __has_include("fieldvision/synth/synth.h")

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

// The median, and a failing value when nothing was measured.
double Median(const std::vector<double>& v) {
  return v.empty() ? 1e9 : util::NearestRankPercentile(v, 0.5);
}

const BallCandidate* BestAccepted(const std::vector<BallCandidate>& c) {
  return !c.empty() && c.front().accepted ? &c.front() : nullptr;
}

// Every fully visible ball of 6-40 px across is found, centred within a pixel. Not at every seed:
// at 2 of seeds 1-12 one ball is rejected, in front of stands or a board of nearly its colour
// ("too little contrast", "region has corners"), the detector's limit of issue 12.
TEST(BallDetectorSynth, SubpixelCentreOverTheSizeRange) {
  const uint64_t seed = fv::testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  synth::SceneSpec spec = synth::Preset("static", seed);
  spec.cameras.resize(2);
  spec.num_frames = 12;
  spec.ball.placements.resize(12);
  const synth::SceneRenderer scene(spec);
  std::vector<std::unique_ptr<BallDetector>> detectors;
  for (const camera::Camera& cam : scene.cameras()) {
    detectors.push_back(
        std::make_unique<BallDetector>(BallDetectorOptions{}, &cam, &scene.field()));
  }
  std::vector<double> err, err_small, err_large;
  int expected = 0, found = 0;
  for (int f = 0; f < scene.num_frames(); ++f) {
    const auto images = scene.Render(f);
    const auto truth = scene.BallTruth(f);
    for (size_t k = 0; k < images.size(); ++k) {
      const auto& t = truth.cameras[k];
      const auto cands = detectors[k]->Detect(images[k]);
      const double d_px = 2 * t.radius_px;
      if (!t.in_front || t.visible_fraction < 0.99 || d_px < 6 || d_px > 40) continue;
      ++expected;
      const BallCandidate* best = BestAccepted(cands);
      if (best == nullptr) {
        ADD_FAILURE() << "no ball: frame " << f << " cam " << k << " truth " << t.uv_px.transpose()
                      << " r " << t.radius_px
                      << (cands.empty() ? "" : " best candidate: " + cands.front().reason);
        continue;
      }
      ++found;
      const double e = (best->centre_px - t.uv_px).norm();
      err.push_back(e);
      (d_px < 15 ? err_small : err_large).push_back(e);
      EXPECT_LT(e, 1.0) << "frame " << f << " cam " << k << " r " << t.radius_px;
      EXPECT_NEAR(best->radius_px, t.radius_px, 0.15 * t.radius_px + 0.5);
      // A window around the ball finds the same centre without reading beyond the window:
      // everything outside it is painted ball-orange.
      const int half = std::max(40, static_cast<int>(6 * t.radius_px));
      const cv::Rect window = cv::Rect(static_cast<int>(t.uv_px.x()) - half,
                                       static_cast<int>(t.uv_px.y()) - half, 2 * half, 2 * half) &
                              cv::Rect(0, 0, images[k].cols, images[k].rows);
      cv::Mat painted(images[k].size(), CV_8UC3, cv::Scalar(0, 110, 255));
      images[k](window).copyTo(painted(window));
      const auto in_window = detectors[k]->Detect(painted, window);
      const BallCandidate* w = BestAccepted(in_window);
      ASSERT_NE(w, nullptr) << "frame " << f << " cam " << k;
      EXPECT_EQ(w->centre_px, best->centre_px) << "frame " << f << " cam " << k;
    }
  }
  std::cout << "synth static: " << found << "/" << expected << " balls found, median centre error "
            << Median(err) << " px (d < 15 px: " << Median(err_small)
            << ", d >= 15 px: " << Median(err_large) << ")\n";
  ASSERT_GE(expected, 10);
  EXPECT_EQ(found, expected);
  EXPECT_LT(Median(err), 0.3);
  EXPECT_LT(Median(err_small), 0.3);
  EXPECT_LT(Median(err_large), 0.3);
}

TEST(BallDetectorSynth, OccludedBallsFoundConeRejectedNoBallNoDetection) {
  const uint64_t seed = fv::testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  synth::SceneSpec spec = synth::Preset("kick", seed);
  spec.cameras.resize(2);
  // The robot in front of the ball (as cam1 sees it) slides sideways before a later kick, so
  // cam1 sees the ball hidden, then partly, then free.
  const Eigen::Vector2d ball = spec.ball.kicks[0].position_m.head<2>();
  const Eigen::Vector2d to_cam = (spec.cameras[0].position_m.head<2>() - ball).normalized();
  const Eigen::Vector2d side(-to_cam.y(), to_cam.x());
  spec.robots[0].path.waypoints_m = {ball + 0.6 * to_cam + 0.1 * side,
                                     ball + 0.6 * to_cam + 0.5 * side};
  spec.robots[0].path.speed_mps = 0.25;
  spec.ball.kicks[0].time_s = 1.6;
  spec.num_frames = 120;
  const synth::SceneRenderer scene(spec);
  std::vector<std::unique_ptr<BallDetector>> detectors;
  for (const camera::Camera& cam : scene.cameras()) {
    detectors.push_back(
        std::make_unique<BallDetector>(BallDetectorOptions{}, &cam, &scene.field()));
  }
  const Eigen::Vector3d cone(spec.cones[0].position_m.x(), spec.cones[0].position_m.y(),
                             0.5 * spec.cones[0].height_m);
  int occluded = 0, occluded_found = 0, cone_checks = 0;
  std::vector<double> err;
  for (int f = 0; f <= 72; f += 6) {
    const auto images = scene.Render(f);
    const auto truth = scene.BallTruth(f);
    for (size_t k = 0; k < images.size(); ++k) {
      const camera::Camera& cam = scene.cameras()[k];
      const auto& t = truth.cameras[k];
      const auto cands = detectors[k]->Detect(images[k]);
      // Nothing accepted on the cone (unless the ball is right there).
      const auto cone_uv = cam.Project(cone);
      if (cone_uv && cam.InImage(*cone_uv) && (!t.in_front || (t.uv_px - *cone_uv).norm() > 30)) {
        ++cone_checks;
        for (const auto& c : cands) {
          if (c.accepted) {
            EXPECT_GT((c.centre_px - *cone_uv).norm(), 25)
                << "cone accepted: frame " << f << " cam " << k << " r " << c.radius_px << " score "
                << c.score << " vis " << c.visible_fraction << " in " << c.inlier_fraction
                << " out " << c.outside_fraction << " at " << c.centre_px.transpose();
          }
        }
      }
      if (!t.in_front || t.radius_px < 3) continue;
      const BallCandidate* best = BestAccepted(cands);
      if (t.visible_fraction >= 0.5 && t.visible_fraction < 0.95) {
        ++occluded;
        if (best != nullptr && (best->centre_px - t.uv_px).norm() < t.radius_px) {
          ++occluded_found;
          err.push_back((best->centre_px - t.uv_px).norm());
        }
      }
    }
  }
  std::cout << "synth kick: " << occluded_found << "/" << occluded
            << " partly occluded balls found, median error " << Median(err) << " px; "
            << cone_checks << " views of the cone\n";
  EXPECT_GT(cone_checks, 0);
  EXPECT_GE(occluded, 3);
  EXPECT_GE(occluded_found, 0.8 * occluded);
  EXPECT_LT(Median(err), 0.5);
  // No ball at all: in 8 images of the empty scene (4 frames, 2 cameras), at most four accept
  // something (stands, robots and the cone are about; seeds 1-40: none at 10, one at 17, two at
  // 11, three at 2, each an orange block of the ball's size in the stands, which the cameras
  // together drop: it hovers; of seeds 41-51 four at 49, one thing of radius 5.8 px in three
  // frames of one camera and once in the other).
  spec.ball.enabled = false;
  spec.num_frames = 4;
  const synth::SceneRenderer empty(spec);
  int with_detection = 0;
  std::string detections;
  for (int f = 0; f < empty.num_frames(); ++f) {
    const auto images = empty.Render(f);
    for (size_t k = 0; k < images.size(); ++k) {
      const std::vector<BallCandidate> candidates = detectors[k]->Detect(images[k]);
      const BallCandidate* best = BestAccepted(candidates);
      if (best == nullptr) continue;
      ++with_detection;
      detections += fmt::format(" frame {} cam {} at ({:.1f}, {:.1f}) r {:.1f};", f, k,
                                best->centre_px.x(), best->centre_px.y(), best->radius_px);
    }
  }
  std::cout << "synth kick without a ball: " << with_detection << " of 8 images with a detection"
            << detections << "\n";
  EXPECT_LE(with_detection, 4) << detections;
}

}  // namespace
}  // namespace fv::detect

#endif  // synth module present
