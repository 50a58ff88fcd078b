// The synthetic world's appearance options render as specified: sun and ambient shading, the
// highlight, printed patterns and their spin, a ball held in a handler, white-balance drift,
// fisheye cameras (and their camera files), and the new keys' JSON round trip and errors.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/synth/figures.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::synth {
namespace {

// One small camera 3 m in front of a ball floating 0.6 m above the ground, looking along +y,
// no noise, vignetting or drift: the ball's radius is about 17 px.
SceneSpec CloseUp(uint64_t seed) {
  SceneSpec s;
  s.seed = seed;
  CameraSpec c;
  c.width = 160;
  c.height = 120;
  c.hfov_deg = 20;
  c.position_m = Eigen::Vector3d(0, -3, 0.6);
  c.look_at_m = Eigen::Vector3d(0, 0, 0.6);
  s.cameras = {c};
  s.num_frames = 1;
  s.ball.placements = {Eigen::Vector3d(0, 0, 0.6)};
  s.ball.orientation_rvec = Eigen::Vector3d(0.3, -0.2, 0.1);
  s.noise_sigma = 0;
  s.lighting.vignetting = 0;
  s.lighting.shadows = false;
  return s;
}

// Pixels of the ball's disc within `share` of its radius (truth centre and radius).
std::vector<cv::Vec3b> DiscPixels(const SceneRenderer& scene, const cv::Mat& img, int frame,
                                  double share) {
  const BallCameraTruth t = scene.BallTruth(frame).cameras[0];
  std::vector<cv::Vec3b> out;
  for (int v = 0; v < img.rows; ++v) {
    for (int u = 0; u < img.cols; ++u) {
      if ((Eigen::Vector2d(u, v) - t.uv_px).norm() < share * t.radius_px) {
        out.push_back(img.at<cv::Vec3b>(v, u));
      }
    }
  }
  return out;
}

std::pair<int, int> RedRange(const std::vector<cv::Vec3b>& px) {
  int lo = 255, hi = 0;
  for (const auto& p : px) {
    lo = std::min<int>(lo, p[2]);
    hi = std::max<int>(hi, p[2]);
  }
  return {lo, hi};
}

TEST(SynthAppearance, SideAwayFromTheSunAtTheAmbientShare) {
  const uint64_t seed = fv::testing::TestSeed(1);
  FV_SEED_TRACE(seed);
  // The sun low on +x: the ball's left limb (seen from -y) faces away from it.
  SceneSpec s = CloseUp(seed);
  s.ball.colour_bgr = Eigen::Vector3d(40, 120, 200);
  s.ball.specular = 0;
  s.lighting.sun_elevation_deg = 10;
  s.lighting.sun_azimuth_deg = 0;
  for (double ambient : {0.35, 0.6}) {
    s.lighting.ambient = ambient;
    const SceneRenderer scene(s);
    EXPECT_NEAR(scene.spec().lighting.Direction().z(), std::sin(10 * M_PI / 180), 1e-12);
    const auto [lo, hi] = RedRange(DiscPixels(scene, scene.RenderCamera(0, 0), 0, 0.85));
    SCOPED_TRACE(::testing::Message() << "ambient " << ambient << " red " << lo << ".." << hi);
    EXPECT_NEAR(lo, ambient * 200, 3);
    EXPECT_LE(hi, 201);
    EXPECT_GE(hi, 0.85 * 200);
  }
  // The fixed shading (ambient < 0) keeps the far side at half the colour.
  s.lighting.ambient = -1;
  const SceneRenderer fixed(s);
  EXPECT_NEAR(RedRange(DiscPixels(fixed, fixed.RenderCamera(0, 0), 0, 0.85)).first, 100, 3);
}

TEST(SynthAppearance, HighlightFollowsStrength) {
  const uint64_t seed = fv::testing::TestSeed(2);
  FV_SEED_TRACE(seed);
  // The sun behind the camera: the highlight lies near the disc's centre.
  SceneSpec s = CloseUp(seed);
  s.ball.colour_bgr = Eigen::Vector3d(30, 60, 120);
  s.lighting.ambient = 0.35;
  s.lighting.sun_elevation_deg = 20;
  s.lighting.sun_azimuth_deg = -90;
  s.ball.shininess = 30;
  int peak[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    s.ball.specular = k == 0 ? 0 : 120;
    const SceneRenderer scene(s);
    const auto px = DiscPixels(scene, scene.RenderCamera(0, 0), 0, 0.9);
    for (const auto& p : px) peak[k] = std::max<int>(peak[k], p[0]);  // blue: 30 without it
  }
  EXPECT_LE(peak[0], 31);
  EXPECT_GE(peak[1], 30 + 0.8 * 120);
}

double DarkShare(const std::vector<cv::Vec3b>& px) {
  int dark = 0;
  for (const auto& p : px) dark += p[0] + p[1] + p[2] < 3 * 100;
  return px.empty() ? 0.0 : static_cast<double>(dark) / px.size();
}

TEST(SynthAppearance, PatternsArePrinted) {
  const uint64_t seed = fv::testing::TestSeed(3);
  FV_SEED_TRACE(seed);
  SceneSpec s = CloseUp(seed);
  s.ball.colour_bgr = Eigen::Vector3d(230, 230, 230);
  s.ball.pattern_bgr = Eigen::Vector3d(20, 20, 20);
  s.ball.specular = 0;
  s.lighting.ambient = 1.0;  // flat: only the print is dark
  for (const std::string& pattern : BallPatternNames()) {
    s.ball.pattern = pattern;
    const SceneRenderer scene(s);
    const double share = DarkShare(DiscPixels(scene, scene.RenderCamera(0, 0), 0, 0.9));
    SCOPED_TRACE(pattern + " dark share " + std::to_string(share));
    if (pattern == "none") {
      EXPECT_EQ(share, 0.0);
    } else {
      // A football's 12 pentagons cover about 28 % of its surface; the print's 3 bands ~20 %.
      EXPECT_GT(share, 0.08);
      EXPECT_LT(share, 0.5);
    }
  }
}

TEST(SynthAppearance, PrintTurnsWithTheKicksSpin) {
  const uint64_t seed = fv::testing::TestSeed(4);
  FV_SEED_TRACE(seed);
  SceneSpec s = CloseUp(seed);
  s.ball.placements.clear();
  s.ball.pattern = "pentagons";
  s.ball.colour_bgr = Eigen::Vector3d(230, 230, 230);
  s.fps = 10;
  s.num_frames = 4;
  KickSpec k;
  k.time_s = 0.1;
  k.position_m = Eigen::Vector3d(0, 0, 0.11);
  k.velocity_mps = Eigen::Vector3d(0, 0, 3.0);  // straight up, seen from the camera
  s.ball.kicks = {k};
  s.ball.physics.drag_coefficient = 0;
  const SceneRenderer still(s);
  s.ball.kicks[0].spin_radps = Eigen::Vector3d(0, 0, 2 * M_PI);  // one turn per second about z
  const SceneRenderer spun(s);
  // A quarter turn 0.25 s after the kick; the flight is the same.
  const Eigen::Matrix3d r0 = geometry::RotationFromRvec(s.ball.orientation_rvec);
  const Eigen::Matrix3d quarter = geometry::RotationFromRvec(Eigen::Vector3d(0, 0, M_PI / 2));
  EXPECT_LT((spun.BallOrientation(0.35) - quarter * r0).norm(), 1e-9);
  EXPECT_LT((spun.BallOrientation(0.05) - r0).norm(), 1e-12);
  EXPECT_LT((still.BallOrientation(0.35) - r0).norm(), 1e-12);
  EXPECT_EQ(spun.BallAt(0.3), still.BallAt(0.3));
  const cv::Mat a = still.RenderCamera(0, 3), b = spun.RenderCamera(0, 3);
  const auto pa = DiscPixels(still, a, 3, 0.8), pb = DiscPixels(spun, b, 3, 0.8);
  ASSERT_EQ(pa.size(), pb.size());
  ASSERT_GT(pa.size(), 50u);
  int changed = 0;
  for (size_t i = 0; i < pa.size(); ++i) changed += cv::norm(pa[i], pb[i], cv::NORM_L1) > 60;
  EXPECT_GT(changed, 0.1 * pa.size());
}

TEST(SynthAppearance, HandlerHoldsAndPartlyHidesTheBall) {
  const uint64_t seed = fv::testing::TestSeed(5);
  FV_SEED_TRACE(seed);
  SceneSpec s = Preset("held", seed);
  ResizeCameras(s, 320, 240);
  s.num_frames = 6;
  const SceneRenderer scene(s);
  int partly = 0;
  for (int f = 0; f < s.num_frames; ++f) {
    const double t = scene.FrameTime(f);
    EXPECT_EQ(scene.BallAt(t), HeldBallCentre(s.robots[0], s.ball.radius_m(), t));
    EXPECT_NEAR(scene.BallAt(t).z(), s.ball.radius_m(), 1e-12);
    for (const auto& c : scene.BallTruth(f).cameras) {
      partly += c.visible_fraction > 0.2 && c.visible_fraction < 0.97;
    }
  }
  EXPECT_GT(partly, 0);
  SceneSpec bad = s;
  bad.robots[0].handler = false;
  EXPECT_NE(fv::testing::ErrorOf([&] { bad.Check(); }).find("ball.held_by"), std::string::npos);
}

TEST(SynthAppearance, WhiteBalanceAndExposureDrift) {
  const uint64_t seed = fv::testing::TestSeed(6);
  FV_SEED_TRACE(seed);
  SceneSpec s = CloseUp(seed);
  s.fps = 4;
  s.num_frames = 2;
  s.lighting.white_balance_amplitude = 0.1;
  s.lighting.white_balance_period_s = 1;  // frame 1 (0.25 s): blue x1.1, red x0.9
  s.lighting.gain_amplitude = 0.05;
  s.lighting.period_s = 1;  // and everything x1.05
  const SceneRenderer scene(s);
  const cv::Mat a = scene.RenderCamera(0, 0), b = scene.RenderCamera(0, 1);
  // Sums over pixels far from clipping.
  double sa[3] = {0, 0, 0}, sb[3] = {0, 0, 0};
  for (int v = 0; v < a.rows; ++v) {
    for (int u = 0; u < a.cols; ++u) {
      const cv::Vec3b pa = a.at<cv::Vec3b>(v, u), pb = b.at<cv::Vec3b>(v, u);
      if (std::max({pa[0], pa[1], pa[2]}) > 200 || std::min({pa[0], pa[1], pa[2]}) < 20) continue;
      for (int ch = 0; ch < 3; ++ch) {
        sa[ch] += pa[ch];
        sb[ch] += pb[ch];
      }
    }
  }
  ASSERT_GT(sa[1], 1000 * 50);
  EXPECT_NEAR(sb[0] / sa[0], 1.1 * 1.05, 0.01);
  EXPECT_NEAR(sb[1] / sa[1], 1.05, 0.01);
  EXPECT_NEAR(sb[2] / sa[2], 0.9 * 1.05, 0.01);
}

TEST(SynthAppearance, FisheyeCamerasLoadBackAndSeeBallsNearTheBorder) {
  const uint64_t seed = fv::testing::TestSeed(7);
  FV_SEED_TRACE(seed);
  // The lens: close to r = f theta.
  const std::vector<double> d = FisheyeDistortion();
  ASSERT_EQ(d.size(), 8u);
  camera::Camera lens = camera::Camera::FromFov(640, 480, 60);
  lens.fx = lens.fy = FisheyeFocalPx(640, 130);
  lens.distortion = d;
  for (double deg : {20.0, 45.0, 65.0, 80.0}) {
    const double th = deg * M_PI / 180;
    const auto uv = lens.ProjectFromCamera(Eigen::Vector3d(std::sin(th), 0, std::cos(th)));
    ASSERT_TRUE(uv.has_value());
    EXPECT_NEAR(uv->x() - lens.cx, lens.fx * th, 0.002 * lens.fx * th) << deg << " deg";
  }
  SceneSpec s = Preset("fisheye", seed);
  ResizeCameras(s, 320, 240);
  s.num_frames = 4;
  const SceneRenderer scene(s);
  const std::string dir = fv::testing::TempDir();
  for (const camera::Camera& cam : scene.cameras()) {
    const std::string path = dir + "/" + cam.name + ".yaml";
    camera::WriteCameraYaml(cam, path);
    const camera::Camera back = camera::ReadCameraYaml(path);
    ASSERT_EQ(back.distortion.size(), 8u);
    for (int f = 0; f < s.num_frames; ++f) {
      const Eigen::Vector3d p = scene.BallAt(scene.FrameTime(f));
      const auto a = cam.Project(p), b = back.Project(p);
      ASSERT_TRUE(a && b);
      EXPECT_LT((*a - *b).norm(), 1e-6) << cam.name << " frame " << f;
    }
  }
  // cam1 sees each ball within 12 % of the width of its border, orange at the truth centre.
  for (int f = 0; f < s.num_frames; ++f) {
    const BallCameraTruth t = scene.BallTruth(f).cameras[0];
    const double border =
        std::min({t.uv_px.x(), t.uv_px.y(), 319 - t.uv_px.x(), 239 - t.uv_px.y()});
    EXPECT_LT(border, 0.12 * 320 + 1) << "frame " << f;
    EXPECT_GT(t.visible_fraction, 0.9) << "frame " << f;
    if (t.radius_px < 2.5) continue;  // too small to keep its colour at the centre pixel
    const cv::Vec3b px = scene.RenderCamera(0, f).at<cv::Vec3b>(
        static_cast<int>(std::lround(t.uv_px.y())), static_cast<int>(std::lround(t.uv_px.x())));
    EXPECT_GT(px[2], px[1] + 40) << "frame " << f << " " << px;
  }
}

TEST(SynthAppearance, NewKeysRoundTripAndNameBadValues) {
  SceneSpec s = Preset("low-sun-kick", 3);
  s.robots[0].handler = true;
  s.robots[0].heading_deg = 30;
  const SceneSpec back = SceneSpecFromJson(SceneSpecToJson(s), "test");
  EXPECT_EQ(SceneSpecToJson(back), SceneSpecToJson(s));
  EXPECT_EQ(back.lighting.sun_elevation_deg, 30);
  EXPECT_EQ(back.lighting.ambient, 0.35);
  EXPECT_EQ(back.ball.pattern, "print");
  EXPECT_EQ(back.ball.kicks[0].spin_radps, s.ball.kicks[0].spin_radps);
  EXPECT_TRUE(back.robots[0].handler);
  // Defaults write none of the new keys.
  const nlohmann::json plain = SceneSpecToJson(Preset("kick", 3));
  EXPECT_FALSE(plain["lighting"].contains("ambient"));
  EXPECT_FALSE(plain["ball"].contains("pattern"));
  auto error_of = [](nlohmann::json j) {
    return fv::testing::ErrorOf([&] { SceneSpecFromJson(j, "scene.json"); });
  };
  nlohmann::json j = SceneSpecToJson(s);
  j["ball"]["pattern"] = "stripes";
  EXPECT_EQ(error_of(j),
            "scene.json: ball.pattern: 'stripes' is not one of none, print, pentagons");
  j = SceneSpecToJson(s);
  j["lighting"]["ambient"] = 1.5;
  EXPECT_NE(error_of(j).find("lighting.ambient: must be in [0, 1]"), std::string::npos);
  j = SceneSpecToJson(s);
  j["lighting"]["sun_elevation_deg"] = 95;
  EXPECT_NE(error_of(j).find("lighting.sun_elevation_deg"), std::string::npos);
  j = SceneSpecToJson(s);
  j["ball"]["specular"] = -1;
  EXPECT_NE(error_of(j).find("ball.specular"), std::string::npos);
  j = SceneSpecToJson(s);
  j["ball"]["kicks"][0]["spin_radps"] = {1e4, 0, 0};
  EXPECT_NE(error_of(j).find("ball.kicks[0].spin_radps"), std::string::npos);
  j = SceneSpecToJson(s);
  j["lighting"]["white_balance_amplitude"] = 0.7;
  EXPECT_NE(error_of(j).find("lighting.white_balance_amplitude"), std::string::npos);
}

}  // namespace
}  // namespace fv::synth
