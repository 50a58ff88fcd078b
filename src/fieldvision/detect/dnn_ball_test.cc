#include "fieldvision/detect/dnn_ball.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "fieldvision/detect/detect_eval.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

BallCandidate Cand(double u, double v, double r, double score, bool accepted) {
  BallCandidate c;
  c.centre_px = {u, v};
  c.radius_px = r;
  c.score = score;
  c.accepted = accepted;
  c.reason = accepted ? "" : "rejected";
  return c;
}

TEST(DnnBallOptions, CheckNamesTheBadField) {
  DnnBallOptions o;
  o.detector = "yolo";
  EXPECT_NE(fv::testing::ErrorOf([&] { o.Check(); }).find("--detector"), std::string::npos);
  o = DnnBallOptions();
  o.crop_px = 100;
  EXPECT_NE(fv::testing::ErrorOf([&] { o.Check(); }).find("crop_px"), std::string::npos);
  o = DnnBallOptions();
  o.confirm_score = 1.5;
  EXPECT_NE(fv::testing::ErrorOf([&] { o.Check(); }).find("confirm_score"), std::string::npos);
  o = DnnBallOptions();
  o.keep_field_share = -0.1;
  EXPECT_NE(fv::testing::ErrorOf([&] { o.Check(); }).find("keep_field_share"), std::string::npos);
  o = DnnBallOptions();
  o.hold_min_radius_px = std::nan("");
  EXPECT_NE(fv::testing::ErrorOf([&] { o.Check(); }).find("hold_min_radius_px"), std::string::npos);
  o = DnnBallOptions();
  o.rescan_step_px = 17;
  EXPECT_NE(fv::testing::ErrorOf([&] { o.Check(); }).find("rescan_step_px"), std::string::npos);
  EXPECT_EQ(fv::testing::ErrorOf([] { DnnBallOptions().Check(); }), "");
}

TEST(CandidateFromBox, CentreAndMeanHalfSide) {
  const BallCandidate c = CandidateFromBox({cv::Rect2d(10, 20, 8, 12), 0.6, 32}, 0.5);
  EXPECT_DOUBLE_EQ(c.centre_px.x(), 14.0);
  EXPECT_DOUBLE_EQ(c.centre_px.y(), 26.0);
  EXPECT_DOUBLE_EQ(c.radius_px, 5.0);
  EXPECT_TRUE(c.accepted);
  EXPECT_DOUBLE_EQ(c.network_score, 0.6);
  EXPECT_FALSE(CandidateFromBox({cv::Rect2d(10, 20, 8, 12), 0.4, 32}, 0.5).accepted);
}

// Random scenes of colour candidates, crop scores and network balls: every rule of the "both"
// stage holds.
TEST(CombineBallCandidates, ConfirmsKeepsOrDemotesAndCompletes) {
  const uint64_t seed = fv::testing::TestSeed(12);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  for (int trial = 0; trial < 50; ++trial) {
    DnnBallOptions o;
    o.detector = "both";
    o.demote_unconfirmed = rng.Uniform() < 0.5;
    o.keep_score = rng.Uniform(0.3, 1.0);
    o.keep_field_share = rng.Uniform() < 0.3 ? 0.0 : rng.Uniform(0.2, 0.8);
    std::vector<BallCandidate> colour;
    std::vector<double> confirm;
    const int n = rng.UniformInt(0, 6);
    for (int i = 0; i < n; ++i) {
      colour.push_back(
          Cand(100 * i + 50, 50, rng.Uniform(3, 20), rng.Uniform(), rng.Uniform() < 0.4));
      colour.back().field_share = rng.Uniform() < 0.3 ? -1.0 : rng.Uniform();
      confirm.push_back(rng.Uniform() < 0.5 ? 0.0 : rng.Uniform());
      // Rejected above the field's edge: confirmed only from accept_score.
      colour.back().off_field = !colour.back().accepted && rng.Uniform() < 0.5;
    }
    std::vector<BallCandidate> net;
    // One on a colour candidate (covered), one far away (completes when strong enough).
    if (n > 0) net.push_back(Cand(colour[0].centre_px.x() + 1, 51, 5, 0.9, true));
    const double far_score = rng.Uniform();
    net.push_back(Cand(50, 400, 6, far_score, true));
    const auto out = CombineBallCandidates(colour, confirm, net, o);
    ASSERT_EQ(out.size(), colour.size() + 1);  // the covered network ball adds nothing
    // Tiers in order: confirmed, kept colour, completing network ball, the rest.
    int last_tier = 0;
    for (const BallCandidate& c : out) {
      int tier = 3;
      const bool from_net = c.centre_px.y() == 400;
      if (from_net) {
        tier = far_score >= o.complete_score ? 2 : 3;
        EXPECT_EQ(c.accepted, far_score >= o.complete_score);
      } else {
        const int i = static_cast<int>(std::lround((c.centre_px.x() - 50) / 100));
        const bool confirmed =
            confirm[i] >=
            (colour[i].off_field ? std::max(o.confirm_score, o.accept_score) : o.confirm_score);
        const bool on_field = o.keep_field_share > 0 && colour[i].field_share >= o.keep_field_share;
        const bool kept = colour[i].accepted &&
                          (!o.demote_unconfirmed || colour[i].score >= o.keep_score || on_field);
        tier = confirmed ? 0 : (kept ? 1 : 3);
        EXPECT_EQ(c.accepted, confirmed || kept) << i;
        EXPECT_EQ(c.network_score, confirm[i]) << i;
        EXPECT_EQ(c.reason.empty(), c.accepted) << i;
      }
      EXPECT_GE(tier, last_tier);
      last_tier = tier;
    }
  }
  EXPECT_NE(fv::testing::ErrorOf([] {
              CombineBallCandidates({Cand(1, 1, 2, 0.5, true)}, {}, {}, DnnBallOptions());
            }).find("1 candidates"),
            std::string::npos);
}

// An unconfirmed colour hit below the keep score stays when the field frames it, else it is
// rejected saying why.
TEST(CombineBallCandidates, AnUnconfirmedCandidateOnTheFieldIsKept) {
  DnnBallOptions o;
  o.detector = "both";
  BallCandidate c = Cand(50, 50, 8, 0.3, true);
  c.field_share = 0.8;
  auto out = CombineBallCandidates({c}, {0.02}, {}, o);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].accepted);
  c.field_share = 0.2;
  out = CombineBallCandidates({c}, {0.02}, {}, o);
  EXPECT_FALSE(out[0].accepted);
  EXPECT_NE(out[0].reason.find("20 % of its ring field"), std::string::npos) << out[0].reason;
  o.keep_field_share = 0.0;  // off: the field share does not keep it
  c.field_share = 1.0;
  EXPECT_FALSE(CombineBallCandidates({c}, {0.02}, {}, o)[0].accepted);
}

// A candidate the colour checks rejected and the network confirmed below its own accept score is
// accepted but marked rescued (multi-view fusion takes it as weak); from the accept score, or
// when colour had accepted it, it is not.
TEST(CombineBallCandidates, ALowConfirmationOfARejectedCandidateIsARescue) {
  DnnBallOptions o;
  o.detector = "both";
  const BallCandidate rejected = Cand(50, 50, 8, 0.0, false);
  const BallCandidate accepted = Cand(50, 50, 8, 0.6, true);
  auto out = CombineBallCandidates({rejected}, {0.2}, {}, o);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].accepted);
  EXPECT_TRUE(out[0].rescued);
  out = CombineBallCandidates({rejected}, {o.accept_score}, {}, o);
  EXPECT_TRUE(out[0].accepted);
  EXPECT_FALSE(out[0].rescued);
  out = CombineBallCandidates({accepted}, {0.2}, {}, o);
  EXPECT_TRUE(out[0].accepted);
  EXPECT_FALSE(out[0].rescued);
  out = CombineBallCandidates({rejected}, {0.05}, {}, o);  // below the confirm score
  EXPECT_FALSE(out[0].accepted);
  EXPECT_FALSE(out[0].rescued);
  // Without rescues (the rescan's extra places) only what colour accepted is confirmed; the
  // network's score is still reported.
  out = CombineBallCandidates({rejected, accepted}, {o.accept_score, 0.2}, {}, o, false);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_TRUE(out[0].accepted);
  EXPECT_DOUBLE_EQ(out[0].network_score, 0.2);
  EXPECT_FALSE(out[1].accepted);
  EXPECT_DOUBLE_EQ(out[1].network_score, o.accept_score);
}

TEST(HoldingScores, ABoxConfirmsTheCandidatesItHoldsOfASimilarSize) {
  DnnBallOptions o;
  const std::vector<BallCandidate> colour = {
      Cand(100, 100, 10, 0.5, true), Cand(300, 100, 2, 0.5, false), Cand(500, 100, 10, 0.5, false)};
  const std::vector<BallCandidate> net = {Cand(104, 98, 12, 0.2, false),  // holds the first
                                          Cand(300, 100, 12, 0.9, true),  // 6x the second's size
                                          Cand(520, 100, 10, 0.8, true),  // beside the third
                                          Cand(101, 100, 9, 0.15, false)};
  const std::vector<double> s = HoldingScores(colour, net, o, 1.0);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_DOUBLE_EQ(s[0], 0.2);
  EXPECT_DOUBLE_EQ(s[1], 0.0);
  EXPECT_DOUBLE_EQ(s[2], 0.0);
  // A candidate under hold_min_radius_px in the network's input is left to its crop: at half
  // scale the 10 px candidate is 5 px there.
  EXPECT_DOUBLE_EQ(HoldingScores(colour, net, o, 0.5)[0], 0.0);
  o.hold_min_radius_px = 0;
  EXPECT_DOUBLE_EQ(HoldingScores(colour, net, o, 0.5)[0], 0.2);
  EXPECT_THROW(HoldingScores(colour, net, o, 0.0), Error);
}

// The network part needs the converted model (`make build`) and the shared RoboCup photos.
class DnnBallOnPhotos : public ::testing::Test {
 protected:
  void SetUp() override {
    try {
      dnn::FindModel("nanodet.onnx");
    } catch (const fv::Error& e) {
      GTEST_SKIP() << "NanoDet model not set up (make build): " << e.what();
    }
    dir_ = fv::testing::SharedDataDir();
    if (dir_.empty() || !std::filesystem::is_directory(dir_ + "/robocup-ball-photos/msl-yellow")) {
      GTEST_SKIP() << "shared RoboCup photos absent";
    }
    dir_ += "/robocup-ball-photos/msl-yellow/20190606-r2";
  }
  // `eval detect` of the photos matching `pattern` with the yellow preset and `detector`.
  static DetectEvalOptions YellowEval(const std::string& pattern, const std::string& detector) {
    DetectEvalOptions o;
    o.video = pattern;
    o.progress = false;
    o.detector.colour = "yellow";
    o.dnn.detector = detector;
    return o;
  }
  // `eval detect` in "both" of the SSL photo NAME.jpg with the orange preset.
  std::string SslDir() const { return dir_ + "/../../ssl-orange"; }
  DetectEvalOptions OrangeEval(const std::string& name) const {
    DetectEvalOptions o;
    o.video = SslDir() + "/images/" + name + ".jpg";
    o.labels.labels = SslDir() + "/labels";
    o.labels.class_id = 1;
    o.progress = false;
    o.detector.colour = "orange";
    o.dnn.detector = "both";
    return o;
  }
  std::string dir_;
};

// Pixels outside the search window are never read: noise there changes nothing.
TEST_F(DnnBallOnPhotos, WindowSearchReadsOnlyTheWindow) {
  std::vector<std::string> images;
  for (const auto& e : std::filesystem::directory_iterator(dir_)) {
    if (e.path().extension() == ".jpg") images.push_back(e.path().string());
  }
  ASSERT_FALSE(images.empty());
  std::sort(images.begin(), images.end());
  const cv::Mat img = cv::imread(images[0]);
  ASSERT_FALSE(img.empty());
  DnnBallOptions o;
  o.detector = "both";
  const DnnBallDetector det(o);
  const cv::Rect roi(img.cols / 4, img.rows / 4, img.cols / 2, img.rows / 2);
  cv::Mat noisy = img.clone();
  cv::Mat outside(img.size(), CV_8UC3);
  cv::RNG(7).fill(outside, cv::RNG::UNIFORM, 0, 255);  // not the global RNG: the same each run
  cv::Mat mask(img.size(), CV_8U, cv::Scalar(255));
  mask(roi).setTo(0);
  outside.copyTo(noisy, mask);
  const std::vector<BallCandidate> probe = {
      Cand(roi.x + 5, roi.y + 5, 30, 0.5, true),
      Cand(roi.x + 0.5 * roi.width, roi.y + 40, 10, 0.5, true)};
  EXPECT_EQ(det.CropScores(img, probe, roi), det.CropScores(noisy, probe, roi));
  const auto a = det.Detect(img, roi), b = det.Detect(noisy, roi);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].centre_px, b[i].centre_px);
}

// Crops are scored as they are and mirrored (DnnBallOptions::mirror_crops): a frame and its
// mirror image give each candidate the same score.
TEST_F(DnnBallOnPhotos, MirroredFrameGivesTheSameCropScores) {
  const std::string name = dir_ + "/cam0_20190606_204236";
  const cv::Mat img = cv::imread(name + ".jpg");
  ASSERT_FALSE(img.empty());
  const std::vector<cv::Rect2d> boxes = ReadYoloFile(name + ".txt", 0, img.cols, img.rows);
  ASSERT_FALSE(boxes.empty());
  const cv::Rect2d& ball = boxes[0];
  const double r = 0.25 * (ball.width + ball.height);
  const std::vector<BallCandidate> cands = {
      Cand(ball.x + 0.5 * ball.width, ball.y + 0.5 * ball.height, r, 0.5, true),
      Cand(0.3 * img.cols, 0.6 * img.rows, 12, 0.5, true)};
  std::vector<BallCandidate> mirrored = cands;
  for (BallCandidate& c : mirrored) c.centre_px.x() = img.cols - c.centre_px.x();
  cv::Mat flipped;
  cv::flip(img, flipped, 1);
  DnnBallOptions o;
  o.detector = "both";
  const DnnBallDetector det(o);
  const std::vector<double> a = det.CropScores(img, cands), b = det.CropScores(flipped, mirrored);
  EXPECT_GT(a[0], o.confirm_score) << "the labelled ball";
  EXPECT_DOUBLE_EQ(a[0], b[0]);
  EXPECT_DOUBLE_EQ(a[1], b[1]);
}

// "both" proposes small spots of a lower contrast than the colour detector alone takes
// (DnnBallOptions::spot_min_contrast): a spot a third of the way from a noisy green carpet to
// orange (contrast about 2.5) is a candidate in "both", none in "colour", and only the network
// accepts it.
TEST_F(DnnBallOnPhotos, BothProposesFainterSmallSpots) {
  const uint64_t seed = fv::testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  const cv::Vec3d carpet(60, 140, 60), orange(0, 128, 255);
  const cv::Vec3d faint = carpet + 0.38 * (orange - carpet);
  cv::Mat noise(160, 160, CV_64FC3);
  cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0.0, 12.0);
  cv::Mat painted(160, 160, CV_64FC3, cv::Scalar(carpet[0], carpet[1], carpet[2]));
  const cv::Point spot(80, 90);
  painted(cv::Rect(spot.x - 1, spot.y - 1, 3, 3)).setTo(cv::Scalar(faint[0], faint[1], faint[2]));
  cv::Mat img;
  cv::Mat(painted + noise).convertTo(img, CV_8UC3);  // rounded and saturated
  BallDetectorOptions colour;
  colour.colour = "orange";
  const auto at_spot = [&](const BallCandidate& c) {
    return c.small && (c.centre_px - Eigen::Vector2d(spot.x, spot.y)).norm() < 2.0;
  };
  const auto near_spot = [&](const std::vector<BallCandidate>& cands) {
    return std::count_if(cands.begin(), cands.end(), at_spot);
  };
  DnnBallOptions o;
  const AnyBallDetector colour_only(colour, o, nullptr, nullptr);
  o.detector = "both";
  const AnyBallDetector both(colour, o, nullptr, nullptr);
  EXPECT_EQ(near_spot(colour_only.Detect(img)), 0);
  EXPECT_EQ(near_spot(both.Detect(img)), 1);
  // Fainter than colour alone takes: accepted only when the network confirms it, also when every
  // colour-accepted candidate is kept (--dnn-keep).
  o.demote_unconfirmed = false;
  const AnyBallDetector keep(colour, o, nullptr, nullptr);
  for (const BallCandidate& c : keep.Detect(img)) {
    if (!at_spot(c)) continue;
    EXPECT_EQ(c.accepted, c.network_score >= o.confirm_score) << c.reason;
  }
}

// Nine MSL photos of one camera (eight with the ball; measured: colour 3 hits of 7 detections,
// dnn 4 of 4, both 5 of 6): the network alone finds a few balls and hardly anything else, and
// "both" finds balls with few false detections.
TEST_F(DnnBallOnPhotos, NetworkFindsBallsAndConfirmsColour) {
  DetectEvalOptions o = YellowEval(dir_ + "/cam0_20190606_2043*.jpg", "dnn");
  const DetectEvalResult net = EvaluateDetector(o);
  ASSERT_EQ(net.with_ball, 8);
  EXPECT_GE(net.hits, 3) << net.Summary(10);
  EXPECT_LE(net.false_detections, 1) << net.Summary(10);
  o.dnn.detector = "both";
  const DetectEvalResult both = EvaluateDetector(o);
  EXPECT_GE(both.hits, 4) << both.Summary(10);
  EXPECT_LE(both.false_detections, 2) << both.Summary(10);
}

// Four MSL photos of 2023 whose balls lie beside or in front of robots: the network confirms two;
// the other two (colour scores 0.32-0.37, printed, partly hidden) are kept because the carpet
// frames them (keep_field_share), and without that rule they are lost.
TEST_F(DnnBallOnPhotos, ColourHitsOnTheCarpetAreKept) {
  DetectEvalOptions o = YellowEval(dir_ + "/../20230709-r5/cam0_20230709_110*.jpg", "both");
  const DetectEvalResult kept = EvaluateDetector(o);
  ASSERT_EQ(kept.with_ball, 4);
  EXPECT_EQ(kept.hits, 4) << kept.Summary(10);
  EXPECT_EQ(kept.false_detections, 0) << kept.Summary(10);
  o.dnn.keep_field_share = 0;
  const DetectEvalResult off = EvaluateDetector(o);
  EXPECT_EQ(off.hits, 2) << off.Summary(10);
}

// An SSL golf ball of a few pixels (00370.jpg, 3.5 px radius) that falls between the fast
// scan's rows: in a frame where nothing is accepted, "both" scans again at every pixel
// (DnnBallOptions::rescan_step_px) and finds it; without the rescan nothing is found.
TEST_F(DnnBallOnPhotos, RescanFindsABallBetweenTheScanRows) {
  DetectEvalOptions o = OrangeEval("00370");
  const DetectEvalResult on = EvaluateDetector(o);
  ASSERT_EQ(on.with_ball, 1);
  EXPECT_EQ(on.hits, 1) << on.Summary(5);
  o.dnn.rescan_step_px = 0;
  const DetectEvalResult off = EvaluateDetector(o);
  EXPECT_EQ(off.hits, 0) << off.Summary(5);
  EXPECT_EQ(off.false_detections, 0) << off.Summary(5);
}

// The whole-frame search's input scale, which hold_min_radius_px is measured in.
TEST_F(DnnBallOnPhotos, InputScaleOfTheWholeFrameSearch) {
  DnnBallOptions o;
  o.detector = "both";
  const DnnBallDetector net(o);
  // A 224 px photo is upscaled to the smallest input (416); a 1280 px frame keeps its width; a
  // window is scaled by its own width.
  EXPECT_DOUBLE_EQ(net.InputScale({224, 224}), 416.0 / 224.0);
  EXPECT_EQ(net.InputSize({224, 224}), cv::Size(416, 416));
  EXPECT_DOUBLE_EQ(net.InputScale({1280, 960}), 1.0);
  EXPECT_DOUBLE_EQ(net.InputScale({1280, 960}, cv::Rect(100, 100, 200, 100)), 416.0 / 200.0);
  EXPECT_THROW(net.InputScale({1280, 960}, cv::Rect(2000, 0, 10, 10)), Error);
}

// Two SSL photos (224 x 224, upscaled to the network's 416) whose ball is elsewhere: a
// whole-frame network box around a far robot (2.3-2.8 px orange spots) does not confirm the spot,
// as it did before hold_min_radius_px.
TEST_F(DnnBallOnPhotos, WholeFrameBoxesDoNotConfirmFarSpots) {
  for (const char* name : {"00109", "00208"}) {
    DetectEvalOptions o = OrangeEval(name);
    const DetectEvalResult now = EvaluateDetector(o);
    EXPECT_EQ(now.false_detections, 0) << name << ": " << now.Summary(10);
    o.dnn.hold_min_radius_px = 0;
    const DetectEvalResult before = EvaluateDetector(o);
    EXPECT_EQ(before.false_detections, 1) << name << ": " << before.Summary(10);
  }
}

}  // namespace
}  // namespace fv::detect
