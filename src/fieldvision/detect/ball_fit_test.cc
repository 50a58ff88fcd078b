#include "fieldvision/detect/ball_fit.h"

#include <algorithm>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

// The median, and a failing value when nothing was measured.
double Median(const std::vector<double>& v) {
  return v.empty() ? 1e9 : util::NearestRankPercentile(v, 0.5);
}

TEST(FitCircle, IgnoresOutliers) {
  const uint64_t seed = fv::testing::TestSeed(2);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const Eigen::Vector2d c(rng.Uniform(10, 90), rng.Uniform(10, 90));
  const double r = rng.Uniform(5, 30);
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < 60; ++i) {
    const double th = rng.Uniform(0, 2 * M_PI);
    const double rr = i % 3 == 0 ? r * rng.Uniform(0.3, 0.8) : r + rng.Normal(0, 0.05);
    pts.push_back(c + rr * Eigen::Vector2d(std::cos(th), std::sin(th)));
  }
  // Start from a rough guess, as FitBall does.
  Eigen::Vector2d centre = c + Eigen::Vector2d(0.4, -0.3);
  double radius = r + 0.3;
  std::vector<char> inlier;
  ASSERT_TRUE(FitCircle(pts, 1.0, &centre, &radius, &inlier));
  EXPECT_LT((centre - c).norm(), 0.05);
  EXPECT_NEAR(radius, r, 0.05);
  for (int i = 0; i < 60; ++i) {
    EXPECT_EQ(inlier[i] != 0, i % 3 != 0 || (pts[i] - c).norm() > r - 1.0);
  }
}

// Points off a circle only inwards (a print's line, the terminator) within the symmetric band:
// a narrower band inside keeps the fit on the outer outline.
TEST(FitCircle, NarrowInsideBandKeepsToTheOuterOutline) {
  const uint64_t seed = fv::testing::TestSeed(3);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const Eigen::Vector2d c(50, 50);
  const double r = 10;
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < 72; ++i) {
    const double th = 2 * M_PI * i / 72;
    // A quarter of the outline lies 0.8 px inside the circle.
    const double rr = (th < M_PI / 2 ? r - 0.8 : r) + rng.Normal(0, 0.05);
    pts.push_back(c + rr * Eigen::Vector2d(std::cos(th), std::sin(th)));
  }
  Eigen::Vector2d both = c, outer = c;
  double r_both = r, r_outer = r;
  std::vector<char> inlier;
  ASSERT_TRUE(FitCircle(pts, 1.0, &both, &r_both, &inlier));
  ASSERT_TRUE(FitCircle(pts, 1.0, &outer, &r_outer, &inlier, 0.5));
  EXPECT_GT((both - c).norm(), 0.2);  // the same band both ways: pulled towards the dent
  EXPECT_LT((outer - c).norm(), 0.05);
  EXPECT_NEAR(r_outer, r, 0.05);
}

// Shaded discs of 6..40 px diameter at random sub-pixel places on a noisy field. A limit of the
// fit, measured over seeds 1-200: 24 fail (12 %), each on a disc that touches a white line (most
// at the corner of the two lines) with less than about 1.5 px of grass between: the outermost
// step is then the line's far edge, whose inside colour 1.5 px in is the ball's rim (up to 0.87
// px off, or under 80 % of the rays on the circle). Taking each step's inside colour only back to
// the next step inwards fixed 17 of them but cost the MSL photos 3 balls and the kick render 0.1
// mm, so it was left.
TEST(FitBall, SubpixelCentreOfShadedDiscs) {
  const uint64_t seed = fv::testing::TestSeed(4);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  std::vector<double> err, radius_err;
  for (int i = 0; i < 40; ++i) {
    cv::Mat img = test_util::FieldImage(120, 120, rng);
    const double r = rng.Uniform(3, 20);
    const Eigen::Vector2d c(rng.Uniform(40, 80), rng.Uniform(40, 80));
    test_util::PaintDisc(img, c, r);
    const Eigen::Vector2d rough = c + Eigen::Vector2d(rng.Uniform(-1, 1), rng.Uniform(-1, 1));
    const BallFit fit =
        FitBall(img, table, table.BallBit(), rough, r * rng.Uniform(0.85, 1.15), nullptr);
    ASSERT_TRUE(fit.ok) << fit.failure << " r=" << r;
    err.push_back((fit.centre_px - c).norm());
    radius_err.push_back(std::abs(fit.radius_px - r));
    EXPECT_FALSE(fit.blurred) << fit.Summary();
    EXPECT_GT(fit.inlier_fraction, 0.8) << fit.Summary();
    EXPECT_GT(fit.sigma_px, 0.0);
    EXPECT_LT(fit.sigma_px, 0.5);
  }
  EXPECT_LT(Median(err), 0.1);
  EXPECT_LT(*std::max_element(err.begin(), err.end()), 0.4);
  EXPECT_LT(Median(radius_err), 0.3);
}

// A low sun: the far side at 25 % of the lit side's brightness, out of the colour class. Its
// outline is found where the ball in shade meets the grass (BallFitOptions::shade_max_offset);
// with the shade test off the circle keeps to the lit part and shifts towards the light.
TEST(FitBall, ShadedSideKeepsItsOutline) {
  const uint64_t seed = fv::testing::TestSeed(6);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("yellow"));
  const cv::Vec3b yellow(20, 215, 245);
  BallFitOptions off;
  off.shade_max_offset = 0;
  std::vector<double> err, err_off, shift, shift_off;
  // PaintDisc's light comes from the upper left (image x and y negative).
  const Eigen::Vector2d to_light = Eigen::Vector2d(-0.4, -0.5).normalized();
  for (int i = 0; i < 30; ++i) {
    cv::Mat img = test_util::FieldImage(120, 120, rng);
    const double r = rng.Uniform(5, 16);
    const Eigen::Vector2d c(rng.Uniform(40, 80), rng.Uniform(40, 80));
    test_util::PaintDisc(img, c, r, yellow, 0.75);
    cv::GaussianBlur(img, img, {0, 0}, 0.6);
    img = test_util::JpegRoundTrip(img, 90);
    const Eigen::Vector2d rough = c + Eigen::Vector2d(rng.Uniform(-1, 1), rng.Uniform(-1, 1));
    const double rough_r = r * rng.Uniform(0.85, 1.15);
    const BallFit fit = FitBall(img, table, table.BallBit(), rough, rough_r, nullptr);
    const BallFit fit_off = FitBall(img, table, table.BallBit(), rough, rough_r, nullptr, off);
    ASSERT_TRUE(fit.ok) << fit.failure << " r=" << r;
    ASSERT_TRUE(fit_off.ok) << fit_off.failure << " r=" << r;
    err.push_back((fit.centre_px - c).norm());
    err_off.push_back((fit_off.centre_px - c).norm());
    shift.push_back((fit.centre_px - c).dot(to_light));
    shift_off.push_back((fit_off.centre_px - c).dot(to_light));
  }
  EXPECT_LT(Median(err), 0.35);
  EXPECT_LT(std::abs(Median(shift)), 0.1);
  EXPECT_GT(Median(err_off), 1.5 * Median(err));  // the lit part alone: shifted towards the light
  // Blurred against a dark background, the ball's edge has its chromaticity at any brightness
  // (a mix with black): it is no shade (not darker than its outside) and the radius holds.
  std::vector<double> radius_err;
  for (int i = 0; i < 10; ++i) {
    cv::Mat img(120, 120, CV_8UC3, cv::Scalar(25, 25, 30));
    const double r = rng.Uniform(3, 12);
    const Eigen::Vector2d c(rng.Uniform(40, 80), rng.Uniform(40, 80));
    test_util::PaintDisc(img, c, r, yellow, 0.3);
    cv::GaussianBlur(img, img, {0, 0}, 1.0);
    img = test_util::JpegRoundTrip(img, 75);
    const BallFit fit = FitBall(img, table, table.BallBit(), c, r, nullptr);
    ASSERT_TRUE(fit.ok) << fit.failure << " r=" << r;
    radius_err.push_back(std::abs(fit.radius_px - r));
  }
  EXPECT_LT(Median(radius_err), 0.3);
  EXPECT_LT(*std::max_element(radius_err.begin(), radius_err.end()), 0.5);
}

// Not at every seed: at 6 of seeds 1-60 (9, 17, 23, 28, 53, 55) a small ball (r 6.5 px) with a
// third hidden fits a motion-blurred ellipse instead (the straight occluder's edge and the round
// side make a stadium shape); requiring soft ends for a blur ellipse fixed that but cost a real MSL
// ball.
TEST(FitBall, PartlyOccludedBallFitsTheFreeOutline) {
  const uint64_t seed = fv::testing::TestSeed(8);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  std::vector<double> err;
  for (int i = 0; i < 12; ++i) {
    cv::Mat img = test_util::FieldImage(120, 120, rng);
    const double r = rng.Uniform(6, 18);
    const Eigen::Vector2d c(rng.Uniform(50, 70), rng.Uniform(50, 70));
    test_util::PaintDisc(img, c, r);
    // A dark robot covering about a third of the ball from the side.
    const int edge = static_cast<int>(c.x() + r * rng.Uniform(0.2, 0.5));
    cv::rectangle(img, cv::Rect(edge, 0, 120 - edge, 120), cv::Scalar(35, 35, 35), cv::FILLED);
    // The blob's rough centre and radius are those of the visible part.
    const BallFit fit =
        FitBall(img, table, table.BallBit(), c + Eigen::Vector2d(-0.3 * r, 0), 0.8 * r, nullptr);
    ASSERT_TRUE(fit.ok) << fit.failure;
    err.push_back((fit.centre_px - c).norm());
    EXPECT_LT(fit.inlier_fraction, 0.85) << fit.Summary();
    EXPECT_GT(fit.sigma_px, 0.0);
  }
  EXPECT_LT(Median(err), 0.3);
}

// A ball cut by the image's left border: its outline inside the image is all on the circle, so
// it is judged round (an occluder, above, still counts against it), and the detector accepts it.
TEST(FitBall, ABallCutByTheImageBorderIsJudgedOnItsOutlineInside) {
  const uint64_t seed = fv::testing::TestSeed(9);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  const BallDetector detector(BallDetectorOptions{}, nullptr, nullptr);
  std::vector<double> err;
  for (int i = 0; i < 12; ++i) {
    cv::Mat img = test_util::FieldImage(120, 120, rng);
    const double r = rng.Uniform(8, 18);
    // 10..30 % of the radius beyond the border.
    const Eigen::Vector2d c(r * rng.Uniform(0.7, 0.9), rng.Uniform(40, 80));
    test_util::PaintDisc(img, c, r);
    const BallFit fit =
        FitBall(img, table, table.BallBit(), c + Eigen::Vector2d(0.2 * r, 0), 0.9 * r, nullptr);
    ASSERT_TRUE(fit.ok) << fit.failure;
    err.push_back((fit.centre_px - c).norm());
    EXPECT_GE(fit.inlier_fraction, 0.85) << fit.Summary();
    const std::vector<BallCandidate> cands = detector.Detect(img);
    ASSERT_FALSE(cands.empty());
    EXPECT_TRUE(cands.front().accepted) << cands.front().reason << " r " << r;
    EXPECT_LT((cands.front().centre_px - c).norm(), 1.0);
  }
  EXPECT_LT(Median(err), 0.3);
}

TEST(FitBall, MotionBlurredBallGivesTheMidExposureCentre) {
  const uint64_t seed = fv::testing::TestSeed(9);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  cv::Mat bg = test_util::FieldImage(160, 160, rng, 0.0);
  const double r = 10;
  const Eigen::Vector2d c(40.3, 119.6);  // clear of the painted lines
  const double th = rng.Uniform(0, M_PI);
  const Eigen::Vector2d dir(std::cos(th), std::sin(th));
  const double length = 14;  // px travelled during the exposure
  cv::Mat acc(bg.size(), CV_32FC3, cv::Scalar(0, 0, 0));
  const int n = 15;
  for (int k = 0; k < n; ++k) {
    cv::Mat img = bg.clone();
    test_util::PaintDisc(img, c + (k / double(n - 1) - 0.5) * length * dir, r);
    cv::Mat f;
    img.convertTo(f, CV_32FC3);
    acc += f / n;
  }
  cv::Mat blurred;
  acc.convertTo(blurred, CV_8UC3);
  const BallFit fit = FitBall(blurred, table, table.BallBit(), c, r + 5, nullptr);
  ASSERT_TRUE(fit.ok) << fit.failure;
  EXPECT_TRUE(fit.blurred) << fit.Summary();
  // Shading smeared along the motion biases the outline a little; the uncertainty says so.
  const double err = (fit.centre_px - c).norm();
  EXPECT_LT(err, 1.0) << fit.Summary();
  EXPECT_LT(err, 2.5 * fit.sigma_px) << fit.Summary();
  EXPECT_NEAR(fit.blur_length_px, length, 4.0);
}

// A sphere near the corner of a wide-angle view projects to an ellipse whose centre is not the
// projection of the sphere centre; the cone fit with the camera removes that bias.
TEST(FitBall, ConeFitIsUnbiasedInPerspective) {
  const ColourTable table(PresetColourSpec("orange"));
  const camera::Camera cam = camera::Camera::FromFov(640, 480, 110.0);
  util::Rng rng(1);
  cv::Mat img = test_util::FieldImage(640, 480, rng);
  const Eigen::Vector3d centre(1.2, 0.85, 1.0);  // 56 degrees off the axis
  const Eigen::Vector2d uv = test_util::PaintSphere(img, cam, centre, 0.08);
  const BallFit with_camera = FitBall(img, table, table.BallBit(), uv, 12, &cam);
  const BallFit without = FitBall(img, table, table.BallBit(), uv, 12, nullptr);
  ASSERT_TRUE(with_camera.ok && without.ok);
  EXPECT_LT((with_camera.centre_px - uv).norm(), 0.1) << with_camera.Summary();
  EXPECT_GT((without.centre_px - uv).norm(), 0.3) << without.Summary();
}

TEST(FitBall, OptionsAreChecked) {
  BallFitOptions o;
  o.inside_share = 0.0;
  EXPECT_THROW(o.Check(), Error);
  o.inside_share = 1.5;
  EXPECT_THROW(o.Check(), Error);
}

}  // namespace
}  // namespace fv::detect
