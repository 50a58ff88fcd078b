// Real-ball appearances drawn by hand (a strong sun's shaded side, a print, a specular
// highlight, an occluder, a small ball, a ball cut by the image edge, JPEG noise) must be
// accepted with a good centre; shapes that are not balls (a cone's triangle, a box, a patch of a
// wall with the ball's hue) must not.
#include "fieldvision/detect/ball_region.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <utility>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

using Eigen::Vector2d;

const BallCandidate* Best(const std::vector<BallCandidate>& c) {
  return !c.empty() && c.front().accepted ? &c.front() : nullptr;
}

std::string Describe(const BallCandidate& c) {
  std::ostringstream s;
  s << "centre (" << c.centre_px.transpose() << ") r " << c.radius_px << " arc " << c.arc_cover
    << " fill " << c.fill << " outside " << c.region_outside << " leak " << c.leak << " contrast "
    << c.contrast << " extent " << c.region_extent << " precise " << c.precise << " score "
    << c.score;
  return s.str();
}

enum class Look { kShaded, kPrinted, kHighlight, kOccluded, kJpeg };

// Paints one ball of the given look at a random place and size; returns its centre and radius.
void PaintBall(cv::Mat& img, Look look, util::Rng& rng, Vector2d* c, double* r) {
  *r = rng.Uniform(6, 30);
  *c = Vector2d(rng.Uniform(60, img.cols - 60), rng.Uniform(60, img.rows - 60));
  // A low sun: the far side at 30 % brightness.
  test_util::PaintDisc(img, *c, *r, test_util::kOrange, look == Look::kShaded ? 0.7 : 0.35);
  if (look == Look::kPrinted) {
    // Dark print patches inside the outline (a logo, panel seams).
    for (int k = 0; k < 3; ++k) {
      const double a = rng.Uniform(0, 2 * M_PI), d = rng.Uniform(0, 0.55) * *r;
      cv::ellipse(img, cv::Point(int(c->x() + d * std::cos(a)), int(c->y() + d * std::sin(a))),
                  cv::Size(int(0.18 * *r) + 1, int(0.1 * *r) + 1), rng.Uniform(0, 180), 0, 360,
                  cv::Scalar(30, 30, 40), cv::FILLED);
    }
  } else if (look == Look::kHighlight) {
    cv::circle(img, cv::Point(int(c->x() - 0.35 * *r), int(c->y() - 0.35 * *r)), int(0.25 * *r) + 1,
               cv::Scalar(245, 250, 255), cv::FILLED, cv::LINE_AA);
  } else if (look == Look::kOccluded) {
    // A robot's dark side covers up to 40 % of the ball's width.
    const int x0 = int(c->x() + 0.2 * *r);
    cv::rectangle(img, cv::Rect(x0, int(c->y() - 2 * *r), int(2 * *r), int(4 * *r)),
                  cv::Scalar(25, 25, 25), cv::FILLED);
  } else if (look == Look::kJpeg) {
    img = test_util::JpegRoundTrip(img, 60);
  }
}

TEST(BallRegion, RealBallLooksAreAccepted) {
  const uint64_t seed = fv::testing::TestSeed(5);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const BallDetector det(BallDetectorOptions{}, nullptr, nullptr);
  const std::vector<std::pair<Look, const char*>> looks = {{Look::kShaded, "shaded"},
                                                           {Look::kPrinted, "printed"},
                                                           {Look::kHighlight, "highlight"},
                                                           {Look::kOccluded, "occluded"},
                                                           {Look::kJpeg, "jpeg"}};
  for (const auto& [look, name] : looks) {
    for (int trial = 0; trial < 6; ++trial) {
      cv::Mat img = test_util::FieldImage(480, 360, rng);
      Vector2d c;
      double r;
      PaintBall(img, look, rng, &c, &r);
      const auto cands = det.Detect(img);
      const BallCandidate* best = Best(cands);
      ASSERT_NE(best, nullptr) << name << " ball r " << r << " not accepted: "
                               << (cands.empty() ? "no candidate" : cands.front().reason);
      // The occluded ball's centre comes from 60 % of its outline.
      const double tol = look == Look::kOccluded ? 0.12 * r + 0.5 : 0.08 * r + 0.5;
      EXPECT_LT((best->centre_px - c).norm(), tol) << name << " r " << r;
      EXPECT_NEAR(best->radius_px, r, 0.2 * r + 0.5) << name;
    }
  }
}

TEST(BallRegion, SmallAndEdgeBalls) {
  const uint64_t seed = fv::testing::TestSeed(6);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const BallDetector det(BallDetectorOptions{}, nullptr, nullptr);
  for (int trial = 0; trial < 5; ++trial) {
    cv::Mat img = test_util::FieldImage(320, 240, rng);
    const Vector2d c(rng.Uniform(40, 280), rng.Uniform(40, 200));
    const double r = rng.Uniform(3.0, 4.5);
    test_util::PaintDisc(img, c, r);
    const auto cands = det.Detect(img);
    const BallCandidate* best = Best(cands);
    ASSERT_NE(best, nullptr) << "small ball r " << r;
    EXPECT_LT((best->centre_px - c).norm(), 0.6) << "r " << r << ": " << Describe(*best);
  }
  // A ball a third of which lies beyond the bottom edge (a fisheye robot camera's handler).
  for (int trial = 0; trial < 4; ++trial) {
    cv::Mat img = test_util::FieldImage(320, 240, rng);
    const double r = rng.Uniform(15, 30);
    const Vector2d c(rng.Uniform(60, 260), 239 - 0.35 * r);
    test_util::PaintDisc(img, c, r);
    const auto cands = det.Detect(img);
    const BallCandidate* best = Best(cands);
    ASSERT_NE(best, nullptr) << "edge ball r " << r << ": "
                             << (cands.empty() ? "no candidate" : cands.front().reason);
    EXPECT_LT((best->centre_px - c).norm(), 0.1 * r + 0.5) << "r " << r;
  }
}

// A ball under a low sun (its shaded side not in the colour class) held by a robot whose dark
// arm hides a third of it: the hidden angles and disc pixels count neither for nor against the
// outline and the fill; counted as missing (hidden_value 0), the same region looks like a
// fragment.
TEST(BallRegion, ShadedBallHeldByADarkRobot) {
  const uint64_t seed = fv::testing::TestSeed(8);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  BallRegionOptions off;
  off.hidden_value = 0;
  for (int trial = 0; trial < 5; ++trial) {
    cv::Mat img = test_util::FieldImage(320, 240, rng);
    const double r = rng.Uniform(12, 28);
    const Vector2d c(rng.Uniform(60, 260), rng.Uniform(60, 180));
    test_util::PaintDisc(img, c, r, test_util::kOrange, 0.7);
    const int arm = static_cast<int>(c.x() - 0.35 * r);  // the arm's edge, left of the centre
    cv::rectangle(img, cv::Point(0, 0), cv::Point(arm, 239), cv::Scalar(20, 22, 24), cv::FILLED);
    const cv::Rect seed_box(arm + 1, static_cast<int>(c.y() - r), static_cast<int>(c.x() + r) - arm,
                            static_cast<int>(2 * r));
    const BallRegion seen = AnalyseBallRegion(img, table, table.BallBit(), seed_box, {});
    const BallRegion counted = AnalyseBallRegion(img, table, table.BallBit(), seed_box, {}, off);
    ASSERT_TRUE(seen.ok) << seen.failure;
    ASSERT_TRUE(counted.ok) << counted.failure;
    SCOPED_TRACE("r " + std::to_string(r) + ": " + seen.Summary() + " / " + counted.Summary());
    EXPECT_LT(seen.seen, 0.8);  // the arm hides about 40 % of the circle's angle
    EXPECT_GT(seen.seen, 0.5);
    EXPECT_EQ(counted.seen, 1.0);
    EXPECT_GT(seen.arc_cover, counted.arc_cover + 0.15);
    EXPECT_GT(seen.fill, counted.fill + 0.15);
    EXPECT_GE(seen.arc_cover, 0.5);
    EXPECT_GE(seen.fill, 0.8);
    EXPECT_LT((seen.centre_px - c).norm(), 0.15 * r + 0.5);
  }
}

// A ball in another robot's handler: the handler's dark bars hide all but a cap of it (under half
// its outline). A cap seen from above is a ball hidden by what stands in front of it and is
// taken, its circle from the cap's arc; the same shape seen from below (a lamp cut by the
// image's top edge or a fisheye's dark border) is not, nor is the cap when half the outline is
// required (well_seen as min_seen), nor a cap whose circle's centre lies beyond the image.
// Balls of 12-24 px, 20-30 % of the radius above the centre seen: passes seeds 1-300 (at 8 px or
// 15 % some seeds see exactly half the circle or under 40 % of it).
TEST(BallRegion, CapAboveAHandlerIsABallACapBelowIsNot) {
  fv::testing::SeededRng rng(11);
  const ColourTable table(PresetColourSpec("orange"));
  BallRegionOptions half;
  half.min_seen = half.well_seen;
  const BallDetector det(BallDetectorOptions{}, nullptr, nullptr);
  for (int trial = 0; trial < 5; ++trial) {
    cv::Mat img = test_util::FieldImage(320, 240, rng);
    const double r = rng.Uniform(12, 24);
    const Vector2d c(rng.Uniform(80, 240), rng.Uniform(70, 170));
    test_util::PaintDisc(img, c, r);
    const int bar_top = static_cast<int>(std::lround(c.y() - rng.Uniform(0.2, 0.3) * r));
    cv::rectangle(img, cv::Point(static_cast<int>(c.x() - 2.5 * r), bar_top),
                  cv::Point(static_cast<int>(c.x() + 2.5 * r), 239), cv::Scalar(20, 22, 24),
                  cv::FILLED);
    const cv::Rect cap(static_cast<int>(c.x() - r), static_cast<int>(c.y() - r),
                       static_cast<int>(2 * r), bar_top - static_cast<int>(c.y() - r));
    const BallRegion held = AnalyseBallRegion(img, table, table.BallBit(), cap, {});
    SCOPED_TRACE("r " + std::to_string(r) + ": " + held.Summary());
    ASSERT_TRUE(held.ok) << held.failure;
    EXPECT_TRUE(held.partly_seen);
    EXPECT_GT(held.seen_rise, 0.5);
    EXPECT_LT((held.centre_px - c).norm(), 0.15 * r + 0.5);
    EXPECT_NEAR(held.radius_px, r, 0.15 * r + 0.5);
    EXPECT_FALSE(AnalyseBallRegion(img, table, table.BallBit(), cap, {}, half).ok);
    const auto cands = det.Detect(img);
    const BallCandidate* best = Best(cands);
    ASSERT_NE(best, nullptr) << (cands.empty() ? "no candidate" : cands.front().reason);
    EXPECT_LT((best->centre_px - c).norm(), 0.15 * r + 0.5) << Describe(*best);
    // Upside down: the cap's lower part seen, the rest hidden above it.
    cv::Mat flipped;
    cv::flip(img, flipped, 0);
    const cv::Rect cap_below(cap.x, img.rows - cap.y - cap.height, cap.width, cap.height);
    const BallRegion below = AnalyseBallRegion(flipped, table, table.BallBit(), cap_below, {});
    EXPECT_FALSE(below.ok);
    EXPECT_LT(below.seen_rise, -0.5) << below.failure;
    // A ball whose centre lies just below the image's bottom edge: its top seen, its centre not.
    cv::Mat edge = test_util::FieldImage(320, 240, rng);
    test_util::PaintDisc(edge, Vector2d(c.x(), 240 + 0.1 * r), r);
    const cv::Rect cap_edge(static_cast<int>(c.x() - r), static_cast<int>(240 - 0.9 * r),
                            static_cast<int>(2 * r), static_cast<int>(0.9 * r));
    const BallRegion cut = AnalyseBallRegion(edge, table, table.BallBit(), cap_edge, {});
    EXPECT_FALSE(cut.ok) << cut.Summary();
    EXPECT_NE(cut.failure.find("centre outside the image"), std::string::npos) << cut.failure;
  }
}

// A reddish orange ball whose one half falls outside the orange class (hue below 6 deg): the
// region grows through the ball's own colour and takes it whole; without that growth it holds
// only the half in the class.
TEST(BallRegion, BallPartlyOutsideItsClassGrowsByItsOwnColour) {
  const uint64_t seed = fv::testing::TestSeed(9);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourTable table(PresetColourSpec("orange"));
  const std::unique_ptr<ColourTable> grow_table =
      std::make_unique<ColourTable>(WidenedBallSpec(PresetColourSpec("orange"), 4.0, 0.6));
  // The same classes in one table (the detector's): the same region.
  const ColourTable one(WithWidenedBall(PresetColourSpec("orange"), 4.0, 0.6));
  const uint8_t one_grow_bit = one.ClassBit(WidenedBallClass(PresetColourSpec("orange")));
  BallRegionOptions off;
  off.own_reach = 0.0;
  for (int trial = 0; trial < 5; ++trial) {
    cv::Mat img = test_util::FieldImage(320, 240, rng);
    const double r = rng.Uniform(8, 25);
    const Vector2d c(rng.Uniform(60, 260), rng.Uniform(60, 180));
    test_util::PaintDisc(img, c, r, cv::Vec3b(0, 36, 240));  // hue 9 deg: in the class
    cv::Mat red = img.clone();
    test_util::PaintDisc(red, c, r, cv::Vec3b(0, 3, 240));  // hue 1 deg: outside it
    red(cv::Rect(0, 0, static_cast<int>(c.x()), img.rows))
        .copyTo(img(cv::Rect(0, 0, static_cast<int>(c.x()), img.rows)));
    const cv::Rect seed_box(static_cast<int>(c.x()), static_cast<int>(c.y() - 0.5 * r),
                            static_cast<int>(0.5 * r), static_cast<int>(r));
    const BallRegion own =
        AnalyseBallRegion(img, table, table.BallBit(), seed_box, {}, {}, grow_table.get());
    const BallRegion half =
        AnalyseBallRegion(img, table, table.BallBit(), seed_box, {}, off, grow_table.get());
    ASSERT_TRUE(own.ok) << own.failure;
    const BallRegion same =
        AnalyseBallRegion(img, one, one.BallBit(), seed_box, {}, {}, &one, one_grow_bit);
    ASSERT_TRUE(same.ok) << same.failure;
    EXPECT_EQ(same.centre_px, own.centre_px);
    EXPECT_EQ(same.radius_px, own.radius_px);
    SCOPED_TRACE("r " + std::to_string(r) + ": " + own.Summary() + " / " +
                 (half.ok ? half.Summary() : half.failure));
    EXPECT_LT((own.centre_px - c).norm(), 0.1 * r + 0.5);
    EXPECT_NEAR(own.radius_px, r, 0.1 * r + 0.5);
    EXPECT_GT(own.fill, 0.85);
    EXPECT_GT(own.arc_cover, 0.8);
    if (half.ok) EXPECT_LT(half.fill, own.fill - 0.2);
  }
}

TEST(BallRegion, ShapesThatAreNotBallsAreRejected) {
  const uint64_t seed = fv::testing::TestSeed(7);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const BallDetector det(BallDetectorOptions{}, nullptr, nullptr);
  const cv::Scalar orange(0, 110, 255);
  for (int trial = 0; trial < 4; ++trial) {
    cv::Mat img = test_util::FieldImage(480, 360, rng);
    const int x = rng.UniformInt(60, 380), y = rng.UniformInt(60, 260);
    const int s = rng.UniformInt(20, 40);  // smaller boxes blur into discs
    switch (trial) {
      case 0: {  // a cone from the side
        const std::vector<cv::Point> tri = {{x - s / 2, y + s}, {x + s / 2, y + s}, {x, y - s}};
        cv::fillConvexPoly(img, tri, orange, cv::LINE_AA);
        break;
      }
      case 1:  // a box
        cv::rectangle(img, cv::Rect(x, y, s, s), orange, cv::FILLED);
        break;
      case 2:  // a bar
        cv::rectangle(img, cv::Rect(x, y, 3 * s, s / 3 + 2), orange, cv::FILLED);
        break;
      default: {  // a disc painted on a wall of nearly its own colour: no contrast
        img(cv::Rect(x - 50, y - 50, 110, 110)).setTo(cv::Scalar(20, 95, 225));
        test_util::PaintDisc(img, Vector2d(x, y), 0.4 * s, test_util::kOrange, 0.0);
        break;
      }
    }
    const auto cands = det.Detect(img);
    EXPECT_EQ(Best(cands), nullptr)
        << "shape " << trial << " accepted: " << Describe(cands.front());
  }
}

TEST(BallRegion, OptionsAreChecked) {
  BallRegionOptions o;
  o.ring_outer = 1.0;
  EXPECT_THROW(o.Check(), Error);
  o = BallRegionOptions{};
  o.min_seen = 0.0;
  EXPECT_THROW(o.Check(), Error);
  o = BallRegionOptions{};
  o.min_seen = 0.6;  // above well_seen
  EXPECT_THROW(o.Check(), Error);
  o = BallRegionOptions{};
  o.min_partly_seen_rise = 1.5;
  EXPECT_THROW(o.Check(), Error);
  o = BallRegionOptions{};
  o.inside_share = 0.0;
  EXPECT_THROW(o.Check(), Error);
  BallDetectorOptions d;
  d.min_contrast = -1;
  EXPECT_THROW(d.Check(), Error);
  d = BallDetectorOptions{};
  d.min_grass_ring = 1.5;
  EXPECT_THROW(d.Check(), Error);
}

// What the region's speed-ups rely on in OpenCV (ball_region.cc): a closing of a part widened
// within the image (the part keeping k + 1 columns on both sides of the region) and a dilation
// of a part that is not BORDER_ISOLATED read the same pixels as the narrower part; fillPoly fills
// one contour as drawContours(FILLED); the Lab conversion of a pixel does not depend on where it
// lies. Random masks and images, compared with the narrower or the original call.
TEST(BallRegion, OpenCvBehaviourTheSpeedUpsRelyOn) {
  std::mt19937 rng(17);
  const auto grow = [](const cv::Rect& r, int g) {
    return cv::Rect(r.x - g, r.y - g, r.width + 2 * g, r.height + 2 * g);
  };
  const auto wider = [](const cv::Rect& r, int cols) {
    const int w = (r.width + 31) / 32 * 32;
    return w <= cols ? cv::Rect(std::min(r.x, cols - w), r.y, w, r.height) : r;
  };
  for (int it = 0; it < 1500; ++it) {
    const int w = 5 + rng() % 70, h = 5 + rng() % 70;
    cv::Mat region(h, w, CV_8U, cv::Scalar(0));
    for (int d = 0, n = 1 + rng() % 4; d < n; ++d) {
      cv::circle(region, {int(rng() % w), int(rng() % h)}, 1 + rng() % 15, 255, -1);
    }
    for (int i = 0, n = rng() % 2 ? w * h / 6 : 0; i < n; ++i) {
      region.at<uint8_t>(rng() % h, rng() % w) = rng() % 2 ? 255 : 0;
    }
    const cv::Rect bounds = cv::boundingRect(region);
    if (bounds.area() == 0) continue;
    const int k = 1 + rng() % 4;
    const cv::Mat ellipse =
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * k + 1, 2 * k + 1));
    const cv::Rect sub = grow(bounds, k + 1) & cv::Rect(0, 0, w, h);
    const cv::Rect wide =
        sub.x == bounds.x - (k + 1) && sub.br().x == bounds.br().x + k + 1 ? wider(sub, w) : sub;
    cv::Mat narrow_closed = region.clone(), wide_closed = region.clone();
    for (auto [img, part_box] : {std::pair{&narrow_closed, sub}, std::pair{&wide_closed, wide}}) {
      cv::Mat part = (*img)(part_box).clone();
      cv::morphologyEx(part, part, cv::MORPH_CLOSE, ellipse);
      part.copyTo((*img)(part_box));
    }
    ASSERT_EQ(cv::countNonZero(narrow_closed != wide_closed), 0) << "closing, case " << it;
    const cv::Rect box(rng() % w, rng() % h, 1, 1);
    const cv::Rect inner = cv::Rect(box.x, box.y, 1 + rng() % (w - box.x), 1 + rng() % (h - box.y));
    cv::Mat near_all, near_part;
    cv::dilate(region, near_all, ellipse);
    const cv::Rect part_box = wider(inner, w);
    cv::dilate(region(part_box), near_part, ellipse);
    ASSERT_EQ(cv::countNonZero(near_all(inner) != near_part(inner - part_box.tl())), 0)
        << "dilation, case " << it;
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(region, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    for (size_t i = 0; i < contours.size(); ++i) {
      cv::Mat drawn(h, w, CV_8U, cv::Scalar(0)), filled(h, w, CV_8U, cv::Scalar(0));
      cv::drawContours(drawn, contours, static_cast<int>(i), 255, cv::FILLED);
      cv::fillPoly(filled, std::vector<std::vector<cv::Point>>{contours[i]}, 255);
      ASSERT_EQ(cv::countNonZero(drawn != filled), 0) << "fill, case " << it;
    }
  }
  cv::Mat bgr(40, 70, CV_8UC3), lab;
  cv::RNG(rng()).fill(bgr, cv::RNG::UNIFORM, 0, 256);  // not the global RNG: follows the seed
  cv::cvtColor(bgr, lab, cv::COLOR_BGR2Lab);
  for (int it = 0; it < 200; ++it) {
    const cv::Rect r(rng() % 60, rng() % 30, 1 + rng() % 10, 1 + rng() % 10);
    cv::Mat part_lab;
    cv::cvtColor(bgr(r), part_lab, cv::COLOR_BGR2Lab);
    ASSERT_EQ(cv::norm(part_lab, lab(r), cv::NORM_INF), 0) << "Lab, case " << it;
  }
}

}  // namespace
}  // namespace fv::detect
