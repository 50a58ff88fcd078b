// Ball detection under the synthetic world's realistic appearance (synth presets low-sun, held):
// a low sun with the far side of the ball at 35 %, a strong highlight, a printed ball, exposure and
// white-balance drift; floors measured on these scenes with a margin (see the report of issue 12).
#include <algorithm>
#include <iostream>
#include <memory>

#if __has_include("fieldvision/synth/synth.h")

#include <gtest/gtest.h>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/ball_fit.h"
#include "fieldvision/detect/test_images.h"
#include "fieldvision/io/io_testing.h"
#include "fieldvision/io/repeated_chroma.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

struct Score {
  int expected = 0, accepted = 0;
  int off_ball = 0;  // accepted candidates not within that distance of the ball
  std::vector<double> err_px;
  double Share() const { return expected > 0 ? static_cast<double>(accepted) / expected : 0.0; }
  double MedianErr() const {
    return err_px.empty() ? 1e9 : util::NearestRankPercentile(err_px, 0.5);
  }
};

// Per image: is an accepted candidate within max(1.5 px, r / 2) of every ball with at least 70 %
// of its disc visible (and a radius of at least 3 px)?
Score ScoreScene(const synth::SceneSpec& spec, const std::string& colour,
                 BallDetectorOptions options = {}) {
  const synth::SceneRenderer scene(spec);
  options.colour = colour;
  std::vector<std::unique_ptr<BallDetector>> detectors;
  for (const camera::Camera& cam : scene.cameras()) {
    detectors.push_back(std::make_unique<BallDetector>(options, &cam, &scene.field()));
  }
  Score s;
  for (int f = 0; f < scene.num_frames(); ++f) {
    const auto images = scene.Render(f);
    const auto truth = scene.BallTruth(f);
    for (size_t k = 0; k < images.size(); ++k) {
      const auto& t = truth.cameras[k];
      const double near_px = std::max(1.5, 0.5 * t.radius_px);
      const std::vector<BallCandidate> candidates = detectors[k]->Detect(images[k]);
      for (const BallCandidate& c : candidates) {
        s.off_ball += c.accepted && !(t.in_front && (c.centre_px - t.uv_px).norm() <= near_px);
      }
      if (!t.in_front || t.visible_fraction < 0.7 || t.radius_px < 3) continue;
      ++s.expected;
      double best = 1e9;
      for (const BallCandidate& c : candidates) {
        if (c.accepted) best = std::min(best, (c.centre_px - t.uv_px).norm());
      }
      if (best <= near_px) {
        ++s.accepted;
        s.err_px.push_back(best);
      } else {
        std::cout << "  missed: frame " << f << " cam " << k << " r " << t.radius_px << " at "
                  << t.uv_px.transpose() << "\n";
      }
    }
  }
  return s;
}

// The low-sun preset cut to its first `frames` placements.
synth::SceneSpec LowSunScene(uint64_t seed, int frames) {
  synth::SceneSpec spec = synth::Preset("low-sun", seed);
  spec.num_frames = frames;
  spec.ball.placements.resize(frames);
  return spec;
}

TEST(BallDetectorAppearance, LowSunPrintedOrangeBall) {
  const uint64_t seed = fv::testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  synth::SceneSpec spec = LowSunScene(seed, 8);
  spec.ball.colour_bgr = Eigen::Vector3d(0, 110, 255);  // orange, printed in dark blue
  synth::ResizeCameras(spec, 960, 720);
  const Score s = ScoreScene(spec, "orange");
  std::cout << "low sun, printed orange ball: accepted " << s.accepted << "/" << s.expected
            << ", median centre error " << s.MedianErr() << " px\n";
  ASSERT_GE(s.expected, 16);
  EXPECT_GE(s.Share(), 0.8);
  EXPECT_LT(s.MedianErr(), 0.8);
}

// Circles kept to the outer outline (BallFitOptions and BallRegionOptions inside_share): on the
// low-sun scene's shaded, printed yellow balls the centres are nearer the truth than with the
// same band inside as outside (mean 0.20 against 0.24 px measured: a print's lines lie inside
// the silhouette; before the shaded side kept its outline, BallFitOptions::shade_max_offset,
// 0.19 against 0.43 px), as many balls are found (19 of 24 both) and fewer other things pass as
// balls (50 against 85).
TEST(BallDetectorAppearance, OuterOutlineCirclesOfShadedPrintedBalls) {
  const uint64_t seed = fv::testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  synth::SceneSpec spec = LowSunScene(seed, 6);
  BallDetectorOptions symmetric;
  symmetric.fit.inside_share = 1.0;
  symmetric.region.inside_share = 1.0;
  const Score outer = ScoreScene(spec, "yellow");
  const Score both = ScoreScene(spec, "yellow", symmetric);
  const double mean = util::Mean(outer.err_px), mean_both = util::Mean(both.err_px);
  std::cout << "low sun, yellow: " << outer.accepted << "/" << outer.expected
            << " balls, centre error mean " << mean << " px, " << outer.off_ball
            << " accepted off the ball (same band both ways: " << both.accepted << ", " << mean_both
            << " px, " << both.off_ball << ")\n";
  ASSERT_GE(outer.expected, 12);
  EXPECT_GE(outer.accepted, both.accepted - 1);
  // Over seeds 1-70 the ratio of the two means is 0.45-1.28 (lower at 57 of 70; 1.28 at 48, the
  // next 1.13; six frames are few balls): the scene's mean is bounded at 1.35 times the
  // symmetric band's.
  EXPECT_LT(mean, 1.35 * mean_both);
  EXPECT_LT(outer.off_ball, 0.85 * both.off_ball);
}

// The outline fit alone, seeded 1.2 px off and 10 % large at every ball of the low-sun scene
// (printed yellow ball, shaded far side, busy stands behind balls in the air): the outline is the
// silhouette, not a print's line or the terminator (first-step edges: median 2.2 px, p90 3.8 px;
// outermost steps: 0.18 px, 0.44 px). A circle kept to the outer outline (inside_share) is
// nearer than one with the same band both ways.
TEST(BallDetectorAppearance, OutlineOfAPrintedShadedBall) {
  const uint64_t seed = fv::testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  synth::SceneSpec spec = LowSunScene(seed, 16);
  const synth::SceneRenderer scene(spec);
  const ColourTable table(PresetColourSpec("yellow"));
  BallFitOptions symmetric;
  symmetric.inside_share = 1.0;
  std::vector<double> err_px, err_symmetric_px;
  int no_fit = 0;
  for (int f = 0; f < scene.num_frames(); ++f) {
    const auto images = scene.Render(f);
    const auto truth = scene.BallTruth(f);
    for (size_t k = 0; k < images.size(); ++k) {
      const auto& t = truth.cameras[k];
      const double margin = 2 * t.radius_px;
      if (!t.in_front || t.visible_fraction < 0.7 || t.radius_px < 4 || t.uv_px.x() < margin ||
          t.uv_px.y() < margin || t.uv_px.x() > images[k].cols - margin ||
          t.uv_px.y() > images[k].rows - margin) {
        continue;
      }
      const Eigen::Vector2d seed_px = t.uv_px + Eigen::Vector2d(1.0, 0.7);
      const BallFit fit = FitBall(images[k], table, table.BallBit(), seed_px, 1.1 * t.radius_px,
                                  &scene.cameras()[k]);
      const BallFit fit_symmetric = FitBall(images[k], table, table.BallBit(), seed_px,
                                            1.1 * t.radius_px, &scene.cameras()[k], symmetric);
      if (!fit.ok || !fit_symmetric.ok) {
        ++no_fit;
        continue;
      }
      err_px.push_back((fit.centre_px - t.uv_px).norm());
      err_symmetric_px.push_back((fit_symmetric.centre_px - t.uv_px).norm());
    }
  }
  ASSERT_GE(err_px.size(), 25u);
  const double median = util::NearestRankPercentile(err_px, 0.5);
  const double p90 = util::NearestRankPercentile(err_px, 0.9);
  const double mean = util::Mean(err_px), mean_symmetric = util::Mean(err_symmetric_px);
  std::cout << "outline fit of printed, shaded balls: " << err_px.size() << " fitted, " << no_fit
            << " not, centre error median " << median << " px, p90 " << p90 << " px, mean " << mean
            << " px (same band both ways: " << mean_symmetric << ")\n";
  // Ball by ball the outer outline is nearer about twice as often (seeds 1-40: 1112 balls against
  // 595), but not in every scene (16 against 19 at seed 24); the scene's mean error is 0.67-1.07
  // times the symmetric band's over those 40 scenes (median 0.90, lower at 36).
  int nearer = 0, farther = 0;
  for (size_t i = 0; i < err_px.size(); ++i) {
    if (std::abs(err_px[i] - err_symmetric_px[i]) < 0.01) continue;
    (err_px[i] < err_symmetric_px[i] ? nearer : farther) += 1;
  }
  std::cout << "  nearer than the same band both ways for " << nearer << " balls, farther for "
            << farther << "\n";
  EXPECT_LE(no_fit, 1);
  EXPECT_LT(median, 0.45);
  EXPECT_LT(p90, 1.5);
  EXPECT_LT(mean, 1.1 * mean_symmetric);
}

// The resting ball of the low-sun kick (the frames before the kick): its underside merges with
// its contact shadow on the grass, and the outermost step at its bottom was the shadow's edge, so
// the cameras' centres were pulled down. Those rays give no point now
// (BallFitOptions::shadow_band_ratio). Per scene the mean vertical error of the cameras' centres
// scatters by up to 0.45 px either way (the shaded side, the print); over eight scenes the rule
// moves the centres up (seeds 2-9, 10-17, 18-25: +0.084 / +0.065 / +0.066 px without it,
// -0.046 / -0.014 / -0.018 px with it; but seeds 33-40: -0.043 -> -0.202 px). Ball 3D p95 on six
// low-sun kick scenes: 5.9-8.9 mm -> 2.5-4.0 mm.
TEST(BallDetectorAppearance, ARestingBallsContactShadowDoesNotPullItsCentreDown) {
  const uint64_t seed0 = fv::testing::TestSeed(2);
  const auto mean = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 1e9 : s / static_cast<double>(v.size());
  };
  std::vector<double> bias, bias_off;
  for (uint64_t seed = seed0; seed < seed0 + 8; ++seed) {
    FV_SEED_TRACE(seed);
    synth::SceneSpec spec = synth::Preset("low-sun-kick", seed);
    spec.num_frames = 2;  // the kick comes at 0.25 s
    const synth::SceneRenderer scene(spec);
    BallDetectorOptions on, off;
    on.colour = off.colour = "yellow";
    off.fit.shadow_band_ratio = 0;
    std::vector<double> dv, dv_off;
    for (size_t k = 0; k < scene.cameras().size(); ++k) {
      const BallDetector det(on, &scene.cameras()[k], &scene.field());
      const BallDetector det_off(off, &scene.cameras()[k], &scene.field());
      for (int f = 0; f < scene.num_frames(); ++f) {
        const auto t = scene.BallTruth(f).cameras[k];
        if (!t.in_front || t.visible_fraction < 0.9 || t.radius_px < 3) continue;
        const cv::Mat image = test_util::JpegRoundTrip(scene.Render(f)[k], spec.jpeg_quality);
        for (auto [d, out] : {std::pair{&det, &dv}, std::pair{&det_off, &dv_off}}) {
          for (const BallCandidate& c : d->Detect(image)) {
            if (c.accepted && (c.centre_px - t.uv_px).norm() <= 0.5 * t.radius_px) {
              out->push_back(c.centre_px.y() - t.uv_px.y());
              break;
            }
          }
        }
      }
    }
    ASSERT_GE(dv.size(), 4u);
    bias.push_back(mean(dv));
    bias_off.push_back(mean(dv_off));
    std::cout << "resting ball in low sun, seed " << seed << ": mean vertical error " << mean(dv)
              << " px (without the shadow rule " << mean(dv_off) << " px)\n";
  }
  std::cout << "over the scenes: " << mean(bias) << " px (without the rule " << mean(bias_off)
            << " px)\n";
  // The rule moves a resting ball's centre up, away from its contact shadow: by 0.06-0.18 px over
  // eight scenes (seeds 1-80 in eights), while the pull without it ranges from -0.04 to +0.17 px
  // over eight scenes: what the rule does to the 3D error is measured in ball_fit.h.
  EXPECT_LT(mean(bias) - mean(bias_off), -0.04);
  EXPECT_LT(std::abs(mean(bias)), 0.25);
}

// Video decoded by OpenCV's FFmpeg reader (4:2:0 chroma repeated over 2x2 pixels) and the same
// frames with the chroma re-upsampled as frame sources deliver them (repeated_chroma.h).
TEST(BallDetectorAppearance, CentresOfFramesWithRepeatedChroma) {
  const uint64_t seed = fv::testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  synth::SceneSpec spec = synth::Preset("kick", seed);
  const synth::SceneRenderer scene(spec);
  BallDetectorOptions options;
  options.colour = "orange";
  std::vector<double> repeated_px, repaired_px;
  for (size_t k = 0; k < scene.cameras().size(); ++k) {
    const BallDetector det(options, &scene.cameras()[k], &scene.field());
    for (int f = 20; f < 140; f += 10) {
      const auto t = scene.BallTruth(f).cameras[k];
      if (!t.in_front || t.visible_fraction < 0.9 || t.radius_px < 3) continue;
      const cv::Mat repeated = io::test_util::RepeatChroma2x2(scene.Render(f)[k]);
      cv::Mat repaired = repeated.clone();
      io::UpsampleRepeatedChroma(&repaired);
      for (auto [image, out] :
           {std::pair{&repeated, &repeated_px},
            std::pair<const cv::Mat*, std::vector<double>*>{&repaired, &repaired_px}}) {
        double best = 1e9;
        for (const BallCandidate& c : det.Detect(*image)) {
          if (c.accepted) best = std::min(best, (c.centre_px - t.uv_px).norm());
        }
        if (best <= 0.5 * t.radius_px) out->push_back(best);
      }
    }
  }
  ASSERT_GE(repeated_px.size(), 20u);
  const double before = util::NearestRankPercentile(repeated_px, 0.5);
  const double after = util::NearestRankPercentile(repaired_px, 0.5);
  std::cout << "kick, chroma repeated: " << repeated_px.size() << " balls, median centre error "
            << before << " px; re-upsampled: " << repaired_px.size() << ", " << after << " px\n";
  // Seeds 1-4: 0.159 / 0.187 / 0.150 / 0.167 -> 0.108 / 0.100 / 0.098 / 0.081 px, the same balls
  // but one (seed 1: 47 -> 46).
  EXPECT_GE(repaired_px.size() + 1, repeated_px.size());
  EXPECT_LT(after, 0.8 * before);
}

TEST(BallDetectorAppearance, BallHeldInAHandler) {
  const uint64_t seed = fv::testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  // A dark robot's arms cover the ball's upper sides, its body the back; balls with at least 70 %
  // of the disc visible must still be found.
  synth::SceneSpec spec = synth::Preset("held", seed);
  spec.num_frames = 8;
  synth::ResizeCameras(spec, 960, 720);
  const Score s = ScoreScene(spec, "orange");
  std::cout << "ball in a handler: accepted " << s.accepted << "/" << s.expected
            << ", median centre error " << s.MedianErr() << " px\n";
  ASSERT_GE(s.expected, 4);
  EXPECT_GE(s.Share(), 0.75);
  EXPECT_LT(s.MedianErr(), 0.8);
}

// A colour spec with all 8 classes has no room for the widened ball class the regions grow
// through: it gets a table of its own (BallDetector::Init), and the detector finds what it finds
// with the class in its main table.
TEST(BallDetectorAppearance, FullColourSpecGrowsThroughATableOfItsOwn) {
  const uint64_t seed = fv::testing::TestSeed(2);
  FV_SEED_TRACE(seed);
  synth::SceneSpec spec = LowSunScene(seed, 4);
  synth::ResizeCameras(spec, 640, 480);
  const synth::SceneRenderer scene(spec);
  const ColourSpec yellow = PresetColourSpec("yellow");
  ColourSpec full = yellow;
  while (full.classes.size() < 8) {  // classes that hold no colour of these scenes
    full.classes.push_back({"unused" + std::to_string(full.classes.size()),
                            {{ColourSpace::kHsv, {300, 254, 254}, {301, 255, 255}}}});
  }
  ASSERT_EQ(WithWidenedBall(full).classes.size(), 8u);  // no room
  const camera::Camera& cam = scene.cameras()[0];
  const BallDetector one_table(BallDetectorOptions(), yellow, &cam, &scene.field());
  const BallDetector two_tables(BallDetectorOptions(), full, &cam, &scene.field());
  int accepted = 0;
  for (int f = 0; f < scene.num_frames(); ++f) {
    const cv::Mat image = scene.RenderCamera(0, f);
    const auto a = one_table.Detect(image), b = two_tables.Detect(image);
    ASSERT_EQ(a.size(), b.size()) << "frame " << f;
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].accepted, b[i].accepted) << "frame " << f << " candidate " << i;
      EXPECT_LT((a[i].centre_px - b[i].centre_px).norm(), 1e-9) << "frame " << f;
      EXPECT_NEAR(a[i].fill, b[i].fill, 1e-12) << "frame " << f;  // the grown region
      accepted += a[i].accepted;
    }
  }
  EXPECT_GT(accepted, 0);
}

}  // namespace
}  // namespace fv::detect

#endif  // __has_include("fieldvision/synth/synth.h")
