#include "fieldvision/detect/ball_detector.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

int Accepted(const std::vector<BallCandidate>& c) {
  return static_cast<int>(std::count_if(c.begin(), c.end(), [](auto& x) { return x.accepted; }));
}

TEST(BallDetector, FindsDrawnBallsAndRejectsATriangle) {
  const uint64_t seed = fv::testing::TestSeed(21);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const BallDetector det(BallDetectorOptions{}, nullptr, nullptr);
  cv::Mat img = test_util::FieldImage(640, 480, rng);
  EXPECT_EQ(Accepted(det.Detect(img)), 0);  // no ball: nothing accepted
  // An orange cone seen from the side: a triangle.
  const std::vector<cv::Point> tri = {{500, 400}, {540, 400}, {520, 340}};
  cv::fillConvexPoly(img, tri, cv::Scalar(0, 80, 255), cv::LINE_AA);
  const Eigen::Vector2d c(rng.Uniform(150, 300), rng.Uniform(150, 300));
  const double r = rng.Uniform(5, 15);
  test_util::PaintDisc(img, c, r);
  const BallDetectionResult res = det.DetectWithSummary(img);
  ASSERT_EQ(res.accepted(), 1) << res.Summary();
  const BallCandidate& best = res.candidates.front();
  EXPECT_TRUE(best.accepted);
  EXPECT_LT((best.centre_px - c).norm(), 0.2);
  EXPECT_NEAR(best.radius_px, r, 0.4);
  EXPECT_GT(best.score, 0.5);
  bool cone_seen = false;
  for (const auto& cand : res.candidates) {
    if ((cand.centre_px - Eigen::Vector2d(520, 380)).norm() < 25) {
      cone_seen = true;
      EXPECT_FALSE(cand.accepted);
      EXPECT_FALSE(cand.reason.empty());
    }
  }
  EXPECT_TRUE(cone_seen);
}

// A square of the ball's colour fails both paths, the region's shape and the outline fit; its
// reason names both (eval detect lists it with a miss).
TEST(BallDetector, ARejectedSquareGivesTheRegionsAndTheOutlinesReasons) {
  const uint64_t seed = fv::testing::TestSeed(29);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const BallDetector det(BallDetectorOptions{}, nullptr, nullptr);
  cv::Mat img = test_util::FieldImage(320, 240, rng);
  const cv::Vec3b orange = test_util::kOrange;
  const int side = static_cast<int>(rng.Uniform(20, 30));
  cv::rectangle(img, cv::Rect(150, 100, side, side), cv::Scalar(orange[0], orange[1], orange[2]),
                cv::FILLED);
  const std::vector<BallCandidate> cands = det.Detect(img);
  ASSERT_FALSE(cands.empty());
  EXPECT_EQ(Accepted(cands), 0);
  const BallCandidate& c = cands.front();
  EXPECT_NE(c.reason.find("region"), std::string::npos) << c.reason;
  EXPECT_NE(c.reason.find("; outline fit: "), std::string::npos) << c.reason;
}

// A disc that fails only the colour contrast is disc-shaped (worth a network's look); a cone is
// not.
TEST(BallDetector, LowContrastDiscIsDiscShapedAConeIsNot) {
  const uint64_t seed = fv::testing::TestSeed(23);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  BallDetectorOptions o;
  o.min_contrast = 300;  // above any CIELAB distance: every region fails the contrast check
  o.min_hue_contrast = 300;
  o.max_fit_rms_px = 1e-6;  // and no outline fit passes: the region path decides
  const BallDetector det(o, nullptr, nullptr);
  cv::Mat img = test_util::FieldImage(640, 480, rng);
  const std::vector<cv::Point> tri = {{500, 400}, {540, 400}, {520, 340}};
  cv::fillConvexPoly(img, tri, cv::Scalar(0, 80, 255), cv::LINE_AA);
  const Eigen::Vector2d c(rng.Uniform(150, 300), rng.Uniform(150, 300));
  test_util::PaintDisc(img, c, rng.Uniform(6, 15));
  const BallDetectionResult res = det.DetectWithSummary(img);
  EXPECT_EQ(res.accepted(), 0) << res.Summary();
  int discs = 0, cones = 0;
  for (const BallCandidate& cand : res.candidates) {
    if ((cand.centre_px - c).norm() < 2) {
      ++discs;
      EXPECT_TRUE(cand.disc_shaped);
      EXPECT_NE(cand.reason.find("contrast"), std::string::npos) << cand.reason;
    } else if ((cand.centre_px - Eigen::Vector2d(520, 380)).norm() < 25) {
      ++cones;
      EXPECT_FALSE(cand.disc_shaped) << cand.reason;
    }
  }
  EXPECT_EQ(discs, 1);
  EXPECT_GE(cones, 1);
}

// A disc of `bgr` (PaintDisc's `shade`) at a random place and size in `img`, and what `det`
// finds in the image.
struct PaintedDisc {
  Eigen::Vector2d centre;
  double radius_px;
  std::vector<BallCandidate> candidates;
  std::string Trace() const {
    const BallCandidate& best = candidates.front();
    return "r " + std::to_string(radius_px) + " contrast " + std::to_string(best.contrast) +
           " hue " + std::to_string(best.hue_contrast) + " " + best.reason;
  }
};
PaintedDisc DetectPaintedDisc(const BallDetector& det, cv::Mat img, const cv::Vec3b& bgr,
                              double shade, util::Rng& rng) {
  PaintedDisc p;
  p.centre = Eigen::Vector2d(rng.Uniform(60, 260), rng.Uniform(60, 180));
  p.radius_px = rng.Uniform(8, 20);
  test_util::PaintDisc(img, p.centre, p.radius_px, bgr, shade);
  p.candidates = det.Detect(img);
  return p;
}

// A plain 320x240 wall of `bgr` with a little sensor noise.
cv::Mat NoisyWall(const cv::Scalar& bgr, util::Rng& rng) {
  cv::Mat wall(240, 320, CV_8UC3, bgr);
  cv::Mat noise(wall.size(), CV_8UC3);
  test_util::FillNormal(noise, rng, 0, 2);
  return wall + noise;
}

// A yellow ball in shade (olive) on grass differs from it little in lightness and chroma but
// much in hue: it stands out by its hue (min_hue_contrast) though its Delta E is below
// min_contrast. A beige patch on a white wall, of the yellow class's pale range, differs in
// lightness and chroma only: rejected. (The ball in shade on sunlit grass is darker than the
// field: the lit-part check, field_brightness.h, is off here as it must be in such light.)
TEST(BallDetector, AShadedBallStandsOutByItsHueAWallPatchDoesNot) {
  const uint64_t seed = fv::testing::TestSeed(25);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  BallDetectorOptions o;
  o.colour = "yellow";
  o.min_lit_field_ratio = 0.0;
  const BallDetector det(o, nullptr, nullptr);
  for (int trial = 0; trial < 4; ++trial) {
    const PaintedDisc p = DetectPaintedDisc(det, test_util::FieldImage(320, 240, rng),
                                            cv::Vec3b(15, 120, 130), 0.3, rng);  // olive
    ASSERT_FALSE(p.candidates.empty());
    const BallCandidate& best = p.candidates.front();
    SCOPED_TRACE(p.Trace());
    EXPECT_LT(best.contrast, o.min_contrast);
    EXPECT_GE(best.hue_contrast, o.min_hue_contrast);
    EXPECT_TRUE(best.accepted);
    EXPECT_LT((best.centre_px - p.centre).norm(), 0.1 * p.radius_px + 0.5);
  }
  for (int trial = 0; trial < 4; ++trial) {
    const PaintedDisc p = DetectPaintedDisc(det, NoisyWall(cv::Scalar(230, 235, 235), rng),
                                            cv::Vec3b(150, 200, 215), 0.95, rng);  // beige
    ASSERT_FALSE(p.candidates.empty());
    const BallCandidate& best = p.candidates.front();
    EXPECT_FALSE(best.accepted) << "contrast " << best.contrast << " hue " << best.hue_contrast;
    EXPECT_LT(best.hue_contrast, o.min_hue_contrast);
  }
}

// A yellow ball in shade against grey stands differs from them in chroma alone (its Delta E and
// Delta H are below min_contrast and min_hue_contrast): accepted. The same disc on a pale wall of
// its own hue (not neutral) is rejected, and so is a coloured spot on a dark ring (an LED on a
// robot) that only the chroma would set apart (min_contrast raised out of the way).
TEST(BallDetector, AShadedBallStandsOutFromGreyStandsByItsChroma) {
  const uint64_t seed = fv::testing::TestSeed(37);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  BallDetectorOptions o;
  o.colour = "yellow";
  o.min_lit_field_ratio = 0.0;
  const BallDetector det(o, nullptr, nullptr);
  const cv::Vec3b olive(40, 110, 120);  // CIELAB L 46, C 39
  const auto detect_on = [&](const BallDetector& d, const cv::Scalar& wall) {
    PaintedDisc p = DetectPaintedDisc(d, NoisyWall(wall, rng), olive, 0.2, rng);
    EXPECT_FALSE(p.candidates.empty());
    return p;
  };
  for (int trial = 0; trial < 4; ++trial) {
    const PaintedDisc p = detect_on(det, cv::Scalar(100, 100, 100));  // grey, L 42
    if (p.candidates.empty()) continue;
    const BallCandidate& best = p.candidates.front();
    SCOPED_TRACE(p.Trace() + " chroma " + std::to_string(best.chroma_contrast));
    EXPECT_LT(best.contrast, o.min_contrast);
    EXPECT_LT(best.hue_contrast, o.min_hue_contrast);
    EXPECT_GE(best.chroma_contrast, o.min_chroma_contrast);
    EXPECT_TRUE(best.accepted);
    EXPECT_LT((best.centre_px - p.centre).norm(), 0.1 * p.radius_px + 0.5);
  }
  for (int trial = 0; trial < 4; ++trial) {
    const PaintedDisc p = detect_on(det, cv::Scalar(70, 100, 105));  // pale olive, C 18
    if (p.candidates.empty()) continue;
    const BallCandidate& best = p.candidates.front();
    EXPECT_FALSE(best.accepted) << p.Trace();
    EXPECT_NE(best.reason.find("contrast"), std::string::npos) << best.reason;
  }
  BallDetectorOptions only_chroma = o;
  only_chroma.min_contrast = 100;
  const BallDetector det_chroma(only_chroma, nullptr, nullptr);
  for (int trial = 0; trial < 4; ++trial) {
    const PaintedDisc grey = detect_on(det_chroma, cv::Scalar(100, 100, 100));
    const PaintedDisc dark = detect_on(det_chroma, cv::Scalar(35, 35, 35));  // L 13
    if (grey.candidates.empty() || dark.candidates.empty()) continue;
    EXPECT_TRUE(grey.candidates.front().accepted) << grey.Trace();
    const BallCandidate& best = dark.candidates.front();
    EXPECT_GE(best.chroma_contrast, o.min_chroma_contrast) << dark.Trace();
    EXPECT_FALSE(best.accepted) << dark.Trace();
  }
}

// A yellow ball seen yellow-green (a greenish camera) on the green field differs from it by less
// than min_contrast and min_hue_contrast, but its ring is field-coloured: it needs only
// field_contrast_factor of them (accepted), also in front of a black robot. The same disc on a
// wall of about the same contrast that is not the field is rejected.
TEST(BallDetector, AYellowGreenBallOnTheFieldIsAcceptedTheSameDiscOffItIsNot) {
  const uint64_t seed = fv::testing::TestSeed(31);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  BallDetectorOptions o;
  o.colour = "yellow";
  const BallDetector det(o, nullptr, nullptr);
  const cv::Vec3b yellow_green(70, 180, 150);  // hue 76 deg, saturation 156
  for (int trial = 0; trial < 4; ++trial) {
    const PaintedDisc p =
        DetectPaintedDisc(det, test_util::FieldImage(320, 240, rng), yellow_green, 0.3, rng);
    ASSERT_FALSE(p.candidates.empty());
    const BallCandidate& best = p.candidates.front();
    SCOPED_TRACE(p.Trace());
    EXPECT_LT(best.contrast, o.min_contrast);
    EXPECT_LT(best.hue_contrast, o.min_hue_contrast);
    EXPECT_TRUE(best.accepted);
    EXPECT_LT((best.centre_px - p.centre).norm(), 0.1 * p.radius_px + 0.5);
  }
  for (int trial = 0; trial < 4; ++trial) {
    // In front of a black robot that fills about 40 % of the ring: dark pixels hide the field
    // rather than frame the ball, so the rest of the ring decides (at most half of it hidden).
    cv::Mat img = test_util::FieldImage(320, 240, rng);
    const Eigen::Vector2d c(rng.Uniform(80, 200), rng.Uniform(60, 180));
    const double r = rng.Uniform(8, 20);
    cv::rectangle(img, cv::Point(static_cast<int>(c.x() - 3 * r), 0),
                  cv::Point(static_cast<int>(c.x() + 3 * r), static_cast<int>(c.y() - 0.2 * r)),
                  cv::Scalar(20, 22, 24), cv::FILLED);
    test_util::PaintDisc(img, c, r, yellow_green, 0.3);
    const std::vector<BallCandidate> cands = det.Detect(img);
    ASSERT_FALSE(cands.empty());
    const BallCandidate& best = cands.front();
    SCOPED_TRACE("r " + std::to_string(r) + " contrast " + std::to_string(best.contrast) + " " +
                 best.reason);
    EXPECT_TRUE(best.accepted);
    EXPECT_LT((best.centre_px - c).norm(), 0.1 * r + 0.5);
  }
  for (int trial = 0; trial < 4; ++trial) {
    // Hue 60 deg, pale: no class.
    const PaintedDisc p =
        DetectPaintedDisc(det, NoisyWall(cv::Scalar(100, 150, 150), rng), yellow_green, 0.3, rng);
    ASSERT_FALSE(p.candidates.empty());
    const BallCandidate& best = p.candidates.front();
    EXPECT_FALSE(best.accepted) << "contrast " << best.contrast << " hue " << best.hue_contrast;
    EXPECT_NE(best.reason.find("contrast"), std::string::npos) << best.reason;
  }
}

// A ball merged with a board of its colour (a sign, a robot's orange part): the blob is not a
// disc, but where a tracker expects the ball, FitAt fits its free outline.
TEST(BallDetector, FitAtFindsABallMergedWithABoardOfItsColourWhereItIsExpected) {
  const uint64_t seed = fv::testing::TestSeed(27);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const BallDetector det(BallDetectorOptions{}, nullptr, nullptr);
  std::vector<double> errors;
  int found = 0;
  constexpr int kTrials = 20;
  int radius_off = 0;  // radius not within 10 % + 0.3 px
  for (int i = 0; i < kTrials; ++i) {
    cv::Mat img = test_util::FieldImage(320, 240, rng);
    const Eigen::Vector2d c(rng.Uniform(120, 200), rng.Uniform(90, 150));
    const double r = rng.Uniform(6, 14);
    // The board covers a third of the ball's width on one side, well past it along the other axis.
    const int side = static_cast<int>(rng.Uniform(0, 4));
    const double near = r / 3.0;  // the board's edge: r - near inside the ball's edge
    cv::Rect board;
    if (side == 0) board = cv::Rect(int(c.x() + near), int(c.y() - 3 * r), int(3 * r), int(6 * r));
    if (side == 1) {
      board = cv::Rect(int(c.x() - near - 3 * r), int(c.y() - 3 * r), int(3 * r), int(6 * r));
    }
    if (side == 2) board = cv::Rect(int(c.x() - 3 * r), int(c.y() + near), int(6 * r), int(3 * r));
    if (side == 3) {
      board = cv::Rect(int(c.x() - 3 * r), int(c.y() - near - 3 * r), int(6 * r), int(3 * r));
    }
    const cv::Vec3b orange = test_util::kOrange;
    cv::rectangle(img, board, cv::Scalar(orange[0], orange[1], orange[2]), cv::FILLED);
    test_util::PaintDisc(img, c, r);
    const Eigen::Vector2d expected =
        c + Eigen::Vector2d(rng.Uniform(-1.5, 1.5), rng.Uniform(-1.5, 1.5));
    const std::optional<BallCandidate> fit = det.FitAt(img, cv::Rect(), expected, 1.1 * r);
    if (!fit) continue;
    ++found;
    EXPECT_TRUE(fit->accepted && fit->guided);
    radius_off += std::abs(fit->radius_px - r) > 0.1 * r + 0.3;
    errors.push_back((fit->centre_px - c).norm());
    // Nothing ball-like on the grass, a radius far from the ball's, a region without the ball.
    EXPECT_FALSE(det.FitAt(img, cv::Rect(), Eigen::Vector2d(40, 40), r)) << "trial " << i;
    EXPECT_FALSE(det.FitAt(img, cv::Rect(), expected, 2.5 * r)) << "trial " << i;
    EXPECT_FALSE(det.FitAt(img, cv::Rect(0, 0, int(c.x()), 240), expected, r)) << "trial " << i;
  }
  EXPECT_GE(found, kTrials - 2);
  ASSERT_FALSE(errors.empty());
  std::sort(errors.begin(), errors.end());
  // Seeds 1-100: all but one of the 20 within 0.7 px; the worst over 1 px at 3 seeds, at most
  // 1.87 px, where a small ball (r 6 px) took in the board's edge: radius 26 % large, the only
  // radius off in the 2000 trials.
  EXPECT_LE(radius_off, 1);
  EXPECT_LT(errors[errors.size() / 2], 0.3);
  EXPECT_LT(errors[errors.size() - 2], 1.0);
  EXPECT_LT(errors.back(), 2.5);
}

// A camera's background (background.h): a disc that fails only the colour contrast is accepted
// where it stands apart from the background, not where it stood in every sampled frame; among
// accepted discs, the one apart from the background goes first.
TEST(BallDetector, TheBackgroundAcceptsALowContrastBallThatCameIntoViewAndRanksItFirst) {
  const uint64_t seed = fv::testing::TestSeed(29);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const cv::Mat base = test_util::FieldImage(320, 240, rng, 0.0);
  const Eigen::Vector2d still(250, 60);
  const auto frame_with = [&](const std::vector<Eigen::Vector2d>& balls, double r) {
    cv::Mat f = base.clone();
    for (const Eigen::Vector2d& c : balls) test_util::PaintDisc(f, c, r);
    return test_util::WithNoise(f, rng, 2.0);
  };
  std::vector<cv::Mat> samples;
  for (int i = 0; i < 7; ++i) {
    samples.push_back(Background::Reduce(frame_with({{30 + 40.0 * i, 200}, still}, 9),
                                         BackgroundOptions{}.scale));
  }
  const Background background(std::move(samples), base.size(), {});
  ASSERT_TRUE(background.usable()) << background.Summary();
  const Eigen::Vector2d ball(rng.Uniform(120, 180), rng.Uniform(100, 150));
  const cv::Mat img = frame_with({ball, still}, 9);
  const auto near = [](const BallCandidate& c, const Eigen::Vector2d& p) {
    return (c.centre_px - p).norm() < 2;
  };

  // The contrasts asked just above the ball's own (it comes within 0.9 of them): every region
  // fails the contrast check, and the ball comes near enough for the background to decide.
  const std::vector<BallCandidate> plain_low = BallDetector({}, nullptr, nullptr).Detect(img);
  const auto on_ball = std::find_if(plain_low.begin(), plain_low.end(),
                                    [&](const BallCandidate& c) { return near(c, ball); });
  ASSERT_NE(on_ball, plain_low.end());
  const auto asking = [&](double share) {
    BallDetectorOptions o;
    o.field_contrast_factor = 1.0;  // the same asked on the grass
    o.min_contrast = on_ball->contrast / share;
    o.min_hue_contrast = on_ball->hue_contrast / share;
    o.min_chroma_contrast = std::abs(on_ball->chroma_contrast) / share;
    return o;
  };
  BallDetector det(asking(0.9), nullptr, nullptr);
  EXPECT_EQ(Accepted(det.Detect(img)), 0);
  det.SetBackground([&] { return &background; });
  const std::vector<BallCandidate> found = det.Detect(img);
  ASSERT_EQ(Accepted(found), 1);
  EXPECT_TRUE(near(found[0], ball) && found[0].apart_from_background) << found[0].reason;
  for (const BallCandidate& c : found) {
    if (near(c, still)) EXPECT_NE(c.reason.find("contrast"), std::string::npos) << c.reason;
  }
  // No usable background: as without one; a ball far from the contrast asked (half of it): the
  // background does not decide.
  det.SetBackground([] { return nullptr; });
  EXPECT_EQ(Accepted(det.Detect(img)), 0);
  BallDetector far(asking(0.5), nullptr, nullptr);
  far.SetBackground([&] { return &background; });
  EXPECT_EQ(Accepted(far.Detect(img)), 0);
  // An accept by the background alone leaves the small-ball stage on: a far ball elsewhere is
  // still found.
  BallDetectorOptions with_small = asking(0.9);
  with_small.small.mode = "on";
  BallDetector small_det(with_small, nullptr, nullptr);
  small_det.SetBackground([&] { return &background; });
  cv::Mat with_far = img.clone();
  const Eigen::Vector2d tiny(60, 50);
  test_util::PaintDisc(with_far, tiny, 2.2, test_util::kOrange, 0.3);
  const std::vector<BallCandidate> small_found = small_det.Detect(with_far);
  EXPECT_TRUE(std::any_of(small_found.begin(), small_found.end(), [&](const BallCandidate& c) {
    return c.accepted && c.small && (c.centre_px - tiny).norm() < 1.5;
  }));
  EXPECT_TRUE(std::any_of(small_found.begin(), small_found.end(), [&](const BallCandidate& c) {
    return c.accepted && c.apart_from_background && near(c, ball);
  }));

  // Both stand out: the still disc is larger and ranks first, until the background says which
  // one came into view.
  BallDetector ranked(BallDetectorOptions{}, nullptr, nullptr);
  cv::Mat two = frame_with({ball}, 7);
  test_util::PaintDisc(two, still, 9);
  const std::vector<BallCandidate> plain = ranked.Detect(two);
  ASSERT_EQ(Accepted(plain), 2);
  EXPECT_TRUE(near(plain[0], still));
  ranked.SetBackground([&] { return &background; });
  const std::vector<BallCandidate> apart_first = ranked.Detect(two);
  ASSERT_EQ(Accepted(apart_first), 2);
  EXPECT_TRUE(near(apart_first[0], ball) && apart_first[0].apart_from_background);
  EXPECT_FALSE(apart_first[1].apart_from_background);
}

// A ball in front of a board of its colour (one region, larger than a ball there) is found by the
// background: the board stood there in every sampled frame, the ball did not. A camera 3 m above
// the field looking straight down, the ball on the ground (10.55 px). With four larger still
// blocks of its colour in the corners (stands), the rejected regions looked into are those that
// changed, not the largest; with a small block instead of the board, a region not much larger
// than the ball is looked into too.
TEST(BallDetector, TheBackgroundFindsABallMergedWithABoardOfItsColour) {
  const uint64_t seed = fv::testing::TestSeed(31);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  camera::Camera cam = camera::Camera::FromFov(320, 240, 60.0);
  cam.has_pose = true;
  cam.cam_from_world.rotation = Eigen::Vector3d(1, -1, -1).asDiagonal();
  cam.cam_from_world.translation = Eigen::Vector3d(0, 0, 3);
  BallDetectorOptions o;
  o.max_height_m = 0.2;  // on the ground
  const double r = cam.fx * 0.11 / (3 - 0.11);
  const cv::Vec3b orange = test_util::kOrange;
  const cv::Scalar orange_bgr(orange[0], orange[1], orange[2]);
  enum Scene { kBoard, kBoardAndBlocks, kPatch };
  for (const Scene scene : {kBoard, kBoardAndBlocks, kPatch}) {
    SCOPED_TRACE(scene == kBoard ? "the board" : scene == kPatch ? "a patch" : "still blocks");
    const bool blocks = scene == kBoardAndBlocks;
    int found_plain = 0, found = 0, off = 0;
    constexpr int kTrials = 10;
    for (int i = 0; i < kTrials; ++i) {
      cv::Mat base = test_util::FieldImage(320, 240, rng, 0.0);
      const Eigen::Vector2d c(rng.Uniform(120, 200), rng.Uniform(90, 150));
      // The patch: a block half behind the ball, a region hardly larger than the ball.
      const cv::Rect board =
          scene == kPatch
              ? cv::Rect(int(c.x() + 0.8 * r), int(c.y() - 0.6 * r), int(1.4 * r), int(1.2 * r))
              : cv::Rect(int(c.x() + r / 3), int(c.y() - 3 * r), int(3 * r), int(6 * r));
      cv::rectangle(base, board, orange_bgr, cv::FILLED);
      if (blocks) {
        for (const cv::Point& corner :
             {cv::Point(0, 0), cv::Point(265, 0), cv::Point(0, 160), cv::Point(265, 160)}) {
          cv::rectangle(base, cv::Rect(corner, cv::Size(55, 80)), orange_bgr, cv::FILLED);
        }
      }
      const auto noisy = [&](const cv::Mat& f) { return test_util::WithNoise(f, rng, 2.0); };
      std::vector<cv::Mat> samples;
      for (int k = 0; k < 7; ++k) samples.push_back(Background::Reduce(noisy(base.clone()), 2));
      const Background background(std::move(samples), base.size(), {});
      cv::Mat img = base.clone();
      test_util::PaintDisc(img, c, r);
      img = noisy(img);
      BallDetector det(o, &cam, nullptr);
      const auto on_ball = [&](const std::vector<BallCandidate>& cands) {
        return !cands.empty() && cands[0].accepted && (cands[0].centre_px - c).norm() < 0.5 * r;
      };
      found_plain += on_ball(det.Detect(img));
      det.SetBackground([&] { return &background; });
      const std::vector<BallCandidate> cands = det.Detect(img);
      if (!on_ball(cands)) continue;
      ++found;
      EXPECT_TRUE(cands[0].apart_from_background);
      off += (cands[0].centre_px - c).norm() > 1.0 || std::abs(cands[0].radius_px - r) > 1.0;
    }
    EXPECT_LE(found_plain, 2);
    EXPECT_GE(found, kTrials - 1);
    EXPECT_LE(off, 1);
  }
}

// More blobs than max_refine: still things of the ball's colour (here 24 larger discs that stood in
// every sampled frame) used up the refinements before the ball (blobs go largest first); with
// the background the blobs that came into view are refined first.
TEST(BallDetector, TheBackgroundRefinesWhatCameIntoViewFirst) {
  const uint64_t seed = fv::testing::TestSeed(33);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  cv::Mat base = test_util::FieldImage(320, 240, rng, 0.0);
  for (int k = 0; k < 24; ++k) {
    test_util::PaintDisc(base, Eigen::Vector2d(20 + 40.0 * (k % 8), 20 + 40.0 * (k / 8)), 9);
  }
  std::vector<cv::Mat> samples;
  for (int k = 0; k < 7; ++k) {
    samples.push_back(Background::Reduce(test_util::WithNoise(base, rng, 2.0), 2));
  }
  const Background background(std::move(samples), base.size(), {});
  ASSERT_TRUE(background.usable()) << background.Summary();
  // A ball of 6 px, and one of 2.5 px (a disc too small to compare at the background's half
  // scale was never counted as changed).
  for (const double radius_px : {6.0, 2.5}) {
    SCOPED_TRACE(::testing::Message() << "ball radius " << radius_px << " px");
    const Eigen::Vector2d ball(rng.Uniform(60, 260), rng.Uniform(190, 215));
    cv::Mat img = base.clone();
    test_util::PaintDisc(img, ball, radius_px);
    img = test_util::WithNoise(img, rng, 2.0);
    BallDetectorOptions o;
    o.max_refine = 8;
    BallDetector det(o, nullptr, nullptr);
    const auto ball_accepted = [&](const std::vector<BallCandidate>& cands) {
      return std::any_of(cands.begin(), cands.end(), [&](const BallCandidate& c) {
        return c.accepted && (c.centre_px - ball).norm() < 1.0;
      });
    };
    EXPECT_FALSE(ball_accepted(det.Detect(img)));
    det.SetBackground([&] { return &background; });
    EXPECT_TRUE(ball_accepted(det.Detect(img)));
  }
}

TEST(BallDetector, BadInputGivesErrors) {
  BallDetectorOptions o;
  o.scan_step_px = 0;
  try {
    o.Check();
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scan_step_px"), std::string::npos);
  }
  o = BallDetectorOptions{};
  o.max_radius_px = 1.0;
  EXPECT_THROW(o.Check(), Error);
  o = BallDetectorOptions{};
  o.diameter_m = std::nan("");
  EXPECT_THROW(o.Check(), Error);
  o = BallDetectorOptions{};
  o.colour = "not-a-colour";
  EXPECT_THROW(BallDetector(o, nullptr, nullptr), Error);
  const camera::Camera cam = camera::Camera::FromFov(320, 240, 60);
  const BallDetector det(BallDetectorOptions{}, &cam, nullptr);
  try {
    det.Detect(cv::Mat(200, 300, CV_8UC3, cv::Scalar(0, 0, 0)));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("frame is 300x200 but camera"), std::string::npos);
  }
  EXPECT_THROW(det.Detect(cv::Mat()), Error);
  EXPECT_THROW(det.Detect(cv::Mat(240, 320, CV_8U)), Error);
}

}  // namespace
}  // namespace fv::detect
