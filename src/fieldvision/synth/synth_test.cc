#include "fieldvision/synth/synth.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/synth/ball_physics.h"
#include "fieldvision/synth/figures.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::synth {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// A small clean scene: two cameras, no noise, lighting or shadows, ball at given places.
SceneSpec CleanScene(const std::vector<Eigen::Vector3d>& places, uint64_t seed) {
  SceneSpec s;
  s.seed = seed;
  s.field = "robocup-msl";
  CameraSpec a;
  a.name = "a";
  a.width = 320;
  a.height = 240;
  a.hfov_deg = 60;
  a.distortion = {-0.05, 0.01, 0, 0, 0};
  a.position_m = Eigen::Vector3d(-8, -6, 4);
  a.look_at_m = Eigen::Vector3d(-2, -1, 0);
  CameraSpec b = a;
  b.name = "b";
  b.distortion.clear();
  b.position_m = Eigen::Vector3d(4, -6.5, 3);
  b.look_at_m = Eigen::Vector3d(-2, 0, 0);
  s.cameras = {a, b};
  s.fps = 30;
  s.num_frames = static_cast<int>(places.size());
  s.ball.placements = places;
  s.noise_sigma = 0;
  s.lighting.gain_amplitude = 0;
  s.lighting.vignetting = 0;
  s.lighting.shadows = false;
  return s;
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(SceneSpec, JsonRoundTripKeepsEverything) {
  for (const auto& name : PresetNames()) {
    const SceneSpec s = Preset(name, 5);
    const nlohmann::json j = SceneSpecToJson(s);
    const SceneSpec back = SceneSpecFromJson(j, "test");
    EXPECT_EQ(SceneSpecToJson(back).dump(), j.dump()) << name;
  }
}

TEST(SceneSpec, BadValuesNameTheKey) {
  nlohmann::json j = SceneSpecToJson(Preset("kick", 1));
  auto error_of = [](const nlohmann::json& jj) -> std::string {
    try {
      SceneSpecFromJson(jj, "scene.json");
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  nlohmann::json bad = j;
  bad["cameras"][1]["width"] = -3;
  EXPECT_NE(error_of(bad).find("cameras[1].width"), std::string::npos) << error_of(bad);
  bad = j;
  bad["ball"]["physics"]["restitution"] = "high";
  EXPECT_NE(error_of(bad).find("ball.physics: key 'restitution'"), std::string::npos)
      << error_of(bad);
  bad = j;
  bad["ball"]["kicks"][0]["velocity_mps"] = {1, 2};
  EXPECT_NE(error_of(bad).find("ball.kicks[0]: key 'velocity_mps'"), std::string::npos)
      << error_of(bad);
  bad = j;
  bad["fps"] = 0;
  EXPECT_NE(error_of(bad).find("fps"), std::string::npos);
  bad = j;
  bad["noise_sigam"] = 1;
  EXPECT_NE(error_of(bad).find("noise_sigam"), std::string::npos);
  bad = j;
  bad["cameras"][0]["distortion"] = {0.1, 0.2, 0.3};
  EXPECT_NE(error_of(bad).find("cameras[0].distortion"), std::string::npos);
  bad = j;
  bad["cameras"][0]["look_at_m"] = bad["cameras"][0]["position_m"];
  EXPECT_NE(error_of(bad).find("cameras[0].look_at_m"), std::string::npos);
  // Under the opaque ground (z down by mistake): it rendered the ball as fully visible.
  bad = j;
  bad["cameras"][0]["position_m"][2] = -4.0;
  EXPECT_NE(error_of(bad).find("cameras[0].position_m: 4 m below the ground"), std::string::npos)
      << error_of(bad);
  EXPECT_THROW(Preset("nope", 1), Error);
  EXPECT_THAT(
      [] { ReadSceneSpec("/nonexistent/scene.json"); },
      ThrowsMessage<Error>(HasSubstr("scene file '/nonexistent/scene.json' does not exist")));
  const std::string broken = fv::testing::TempDir() + "/broken_scene.json";
  std::ofstream(broken) << "{\"fps\": 30,";
  EXPECT_THAT([&] { ReadSceneSpec(broken); },
              ThrowsMessage<Error>(HasSubstr("scene file '" + broken + "' is not valid JSON")));
}

TEST(BallPhysics, NoDragKickIsTheClosedFormParabola) {
  fv::testing::SeededRng rng(3);
  BallSpec ball;
  ball.physics.drag_coefficient = 0;
  KickSpec k;
  k.time_s = rng.Uniform(0, 0.5);
  k.position_m = Eigen::Vector3d(rng.Uniform(-5, 5), rng.Uniform(-3, 3), ball.radius_m());
  k.velocity_mps = Eigen::Vector3d(rng.Uniform(-8, 8), rng.Uniform(-8, 8), rng.Uniform(3, 9));
  ball.kicks = {k};
  const BallTrajectory traj(ball, 4.0);
  const double g = ball.physics.gravity_mps2;
  const double t_land = 2 * k.velocity_mps.z() / g;
  for (int i = 0; i <= 100; ++i) {
    const double dt = t_land * i / 100.0;
    Eigen::Vector3d expect = k.position_m + dt * k.velocity_mps;
    expect.z() -= 0.5 * g * dt * dt;
    EXPECT_LT((traj.PositionAt(k.time_s + dt) - expect).norm(), 1e-4) << "dt=" << dt;
  }
  ASSERT_GE(traj.flights().size(), 1u);
  const Flight& f = traj.flights()[0];
  EXPECT_NEAR(f.t_start_s, k.time_s, 1e-9);
  EXPECT_NEAR(f.t_end_s - f.t_start_s, t_land, 1e-6);
  EXPECT_NEAR(f.apex.z(), ball.radius_m() + k.velocity_mps.z() * k.velocity_mps.z() / (2 * g),
              1e-4);
  // Before the kick the ball rests.
  EXPECT_LT((traj.PositionAt(0.5 * k.time_s) - k.position_m).norm(), 1e-12);
}

TEST(BallPhysics, BouncesLoseEnergyAndFlightsTouchTheGround) {
  fv::testing::SeededRng rng(4);
  BallSpec ball;
  KickSpec k;
  k.time_s = 0.1;
  k.position_m = Eigen::Vector3d(-5, 0, ball.radius_m());
  k.velocity_mps = Eigen::Vector3d(rng.Uniform(3, 8), rng.Uniform(-2, 2), rng.Uniform(5, 9));
  ball.kicks = {k};
  const BallTrajectory traj(ball, 6.0);
  const auto& fl = traj.flights();
  ASSERT_GE(fl.size(), 3u);
  const double g = ball.physics.gravity_mps2, m = ball.physics.mass_kg;
  auto energy = [&](const Eigen::Vector3d& v, const Eigen::Vector3d& p) {
    return 0.5 * m * v.squaredNorm() + m * g * p.z();
  };
  for (size_t i = 0; i < fl.size(); ++i) {
    EXPECT_NEAR(fl[i].origin.z(), ball.radius_m(), 1e-9) << i;
    EXPECT_NEAR(fl[i].landing.z(), ball.radius_m(), 1e-9) << i;
    EXPECT_GT(fl[i].apex.z(), ball.radius_m()) << i;
    EXPECT_GT(fl[i].t_end_s, fl[i].t_start_s);
    if (i > 0) {
      EXPECT_NEAR(fl[i].t_start_s, fl[i - 1].t_end_s, 1e-9);
      EXPECT_LT(energy(fl[i].v0_mps, fl[i].origin), energy(fl[i - 1].v0_mps, fl[i - 1].origin));
      EXPECT_LT(fl[i].apex.z(), fl[i - 1].apex.z());
    }
    // The trajectory passes through the contact points.
    EXPECT_LT((traj.PositionAt(fl[i].t_end_s) - fl[i].landing).norm(), 1e-6);
  }
  // In the end the ball rolls to rest on the ground.
  const Eigen::Vector3d end = traj.PositionAt(40.0);
  EXPECT_NEAR(end.z(), ball.radius_m(), 1e-9);
  EXPECT_LT(traj.VelocityAt(40.0).norm(), 1e-9);
}

TEST(Renderer, BallCentreProjectsInsideItsBlob) {
  const uint64_t seed = fv::testing::TestSeed(7);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  std::vector<Eigen::Vector3d> places;
  places.reserve(4);
  for (int i = 0; i < 4; ++i) {
    places.push_back(Eigen::Vector3d(rng.Uniform(-4, 0), rng.Uniform(-3, 1), rng.Uniform(0.3, 2)));
  }
  const SceneRenderer scene(CleanScene(places, seed));
  int checked = 0;
  for (int f = 0; f < scene.num_frames(); ++f) {
    const std::vector<cv::Mat> images = scene.Render(f);
    const BallTruthFrame truth = scene.BallTruth(f);
    ASSERT_TRUE(truth.present);
    EXPECT_LT((truth.centre_m - places[f]).norm(), 1e-12);
    for (size_t c = 0; c < images.size(); ++c) {
      const BallCameraTruth& bt = truth.cameras[c];
      const camera::Camera& cam = scene.cameras()[c];
      if (!bt.in_front || !cam.InImage(bt.uv_px, bt.radius_px + 2)) continue;
      // The projection agrees with the camera model.
      EXPECT_LT((*cam.Project(truth.centre_m) - bt.uv_px).norm(), 1e-9);
      EXPECT_GT(bt.visible_fraction, 0.95);
      cv::Mat diff;
      cv::absdiff(images[c], scene.Background(c), diff);
      cv::Mat gray;
      cv::cvtColor(diff, gray, cv::COLOR_BGR2GRAY);
      const cv::Mat blob = gray > 12;
      const int u = static_cast<int>(std::lround(bt.uv_px.x()));
      const int v = static_cast<int>(std::lround(bt.uv_px.y()));
      EXPECT_TRUE(blob.at<uint8_t>(v, u)) << "camera " << c << " frame " << f;
      const cv::Moments mo = cv::moments(blob, true);
      ASSERT_GT(mo.m00, 0);
      const Eigen::Vector2d centroid(mo.m10 / mo.m00, mo.m01 / mo.m00);
      EXPECT_LT((centroid - bt.uv_px).norm(), 1.0) << "camera " << c << " frame " << f;
      // The blob's area matches the apparent radius.
      EXPECT_NEAR(std::sqrt(mo.m00 / M_PI), bt.radius_px, 0.2 * bt.radius_px + 1.0);
      ++checked;
    }
  }
  EXPECT_GE(checked, 4);
}

TEST(Renderer, BallBehindARobotIsNotVisible) {
  const Eigen::Vector3d ball(-2, -1, 0.11);
  SceneSpec s = CleanScene({ball}, 1);
  // A robot between camera a and the ball, close to the ball.
  const Eigen::Vector2d to_cam = (s.cameras[0].position_m.head<2>() - ball.head<2>()).normalized();
  RobotSpec r;
  r.path.waypoints_m = {ball.head<2>() + 0.5 * to_cam};
  s.robots = {r};
  const SceneRenderer scene(s);
  const BallTruthFrame t = scene.BallTruth(0);
  EXPECT_LT(t.cameras[0].visible_fraction, 0.05);
  EXPECT_GT(t.cameras[1].visible_fraction, 0.9);
  EXPECT_EQ(t.n_cams, 1);
}

TEST(Renderer, PaintedLinesAreWhiteAndGrassIsGreen) {
  const SceneRenderer scene(CleanScene({Eigen::Vector3d(30, 30, 0.11)}, 1));
  const field::FieldModel& field = scene.field();
  int white = 0, green = 0;
  for (size_t c = 0; c < scene.cameras().size(); ++c) {
    const camera::Camera& cam = scene.cameras()[c];
    const cv::Mat img = scene.RenderCamera(static_cast<int>(c), 0);
    for (const Eigen::Vector2d& p : field.SampleLines(0.5)) {
      const auto uv = cam.Project(Eigen::Vector3d(p.x(), p.y(), 0));
      if (!uv || !cam.InImage(*uv, 2)) continue;
      // Only where the line is at least ~2 px wide in the image.
      if (field.line_width_m / cam.PixelFootprintM(Eigen::Vector3d(p.x(), p.y(), 0)) < 4) continue;
      const cv::Vec3b& px = img.at<cv::Vec3b>(static_cast<int>(std::lround(uv->y())),
                                              static_cast<int>(std::lround(uv->x())));
      EXPECT_GT(std::min({px[0], px[1], px[2]}), 150) << "line point " << p.transpose();
      ++white;
    }
    util::Rng rng(11);
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector2d p(rng.Uniform(-9, 9), rng.Uniform(-6, 6));
      if (field.DistanceToPaint(p) < 0.5) continue;
      const auto uv = cam.Project(Eigen::Vector3d(p.x(), p.y(), 0));
      if (!uv || !cam.InImage(*uv, 2)) continue;
      const cv::Vec3b& px = img.at<cv::Vec3b>(static_cast<int>(std::lround(uv->y())),
                                              static_cast<int>(std::lround(uv->x())));
      EXPECT_GT(px[1], px[0] + 30) << "grass point " << p.transpose();
      EXPECT_GT(px[1], px[2] + 30) << "grass point " << p.transpose();
      ++green;
    }
  }
  EXPECT_GE(white, 5);
  EXPECT_GE(green, 50);
}

TEST(Renderer, MotionBlurSpreadsTheBall) {
  SceneSpec s = Preset("kick", 2);
  ResizeCameras(s, 320, 240);
  s.robots.clear();
  s.noise_sigma = 0;
  s.lighting.gain_amplitude = 0;
  s.num_frames = 40;
  s.exposure_s = 1.0 / s.fps;  // long exposure: several pixels of motion at this size
  const double t_mid_flight = s.ball.kicks[0].time_s + 0.3;
  const int frame = static_cast<int>(std::lround(t_mid_flight * s.fps));
  SceneSpec sharp = s;
  sharp.exposure_s = 0;
  const SceneRenderer blurred(s), crisp(sharp);
  int wider = 0;
  for (int c = 0; c < 4; ++c) {
    const BallCameraTruth bt = crisp.CameraTruth(c, frame).ball;
    if (!bt.in_front || !crisp.cameras()[c].InImage(bt.uv_px, bt.radius_px + 5)) continue;
    auto area = [&](const SceneRenderer& r) {
      cv::Mat diff, gray;
      cv::absdiff(r.RenderCamera(c, frame), r.Background(c), diff);
      cv::cvtColor(diff, gray, cv::COLOR_BGR2GRAY);
      return cv::countNonZero(gray > 4);
    };
    if (area(blurred) > area(crisp)) ++wider;
  }
  EXPECT_GE(wider, 1);
}

TEST(Renderer, PlayerBoxesContainTheFigures) {
  SceneSpec s = Preset("players", 3);
  ResizeCameras(s, 320, 240);
  s.num_frames = 5;
  const SceneRenderer scene(s);
  const camera::Camera& cam = scene.cameras()[0];
  int checked = 0;
  for (int f = 0; f < 5; f += 2) {
    const std::vector<PersonTruth> truth = scene.PlayerTruth(f);
    ASSERT_EQ(truth.size(), s.people.size());
    for (size_t i = 0; i < truth.size(); ++i) {
      const PersonTruth& p = truth[i];
      EXPECT_EQ(p.id, s.people[i].id);
      const PlayerCameraTruth& pc = p.cameras[0];
      const auto foot = cam.Project(Eigen::Vector3d(p.x_m, p.y_m, 0.02));
      const auto head = cam.Project(Eigen::Vector3d(p.x_m, p.y_m, 0.9 * s.people[i].height_m));
      if (!foot || !head || !cam.InImage(*foot, 3) || !cam.InImage(*head, 3)) continue;
      ASSERT_TRUE(pc.in_image);
      EXPECT_GT(pc.visible_fraction, 0.0);
      EXPECT_LE(pc.visible_fraction, 1.0);
      for (const auto& q : {*foot, *head}) {
        EXPECT_GE(q.x(), pc.bb_left - 2);
        EXPECT_LE(q.x(), pc.bb_left + pc.bb_width + 2);
        EXPECT_GE(q.y(), pc.bb_top - 2);
        EXPECT_LE(q.y(), pc.bb_top + pc.bb_height + 2);
      }
      // Upright figures: taller than wide.
      EXPECT_GT(pc.bb_height, pc.bb_width);
      ++checked;
    }
  }
  EXPECT_GE(checked, 5);
}

TEST(Presets, KickHasLongFlightsAndAnOccludedMoment) {
  SceneSpec s = Preset("kick", fv::testing::TestSeed(1));
  FV_SEED_TRACE(s.seed);
  EXPECT_EQ(s.cameras.size(), 4u);
  EXPECT_EQ(s.cameras[0].width, 1280);
  ResizeCameras(s, 160, 120);
  // Flights of the whole preset.
  const BallTrajectory traj(s.ball, s.duration_s());
  int long_flights = 0;
  for (const Flight& f : traj.flights()) long_flights += f.t_end_s - f.t_start_s >= 0.25;
  EXPECT_GE(long_flights, 2);
  ASSERT_FALSE(traj.flights().empty());
  EXPECT_GT(traj.flights()[0].apex.z(), 2.0);
  EXPECT_LT(traj.flights()[0].apex.z(), 4.0);
  for (const Flight& f : traj.flights()) {
    EXPECT_LT(f.t_start_s, s.duration_s());
    EXPECT_LT(std::abs(f.landing.x()), 9.0);  // lands on the field
    EXPECT_LT(std::abs(f.landing.y()), 6.0);
  }
  s.num_frames = 3;  // the start: the ball rests behind a robot as seen from cam1
  const SceneRenderer scene(s);
  const BallTruthFrame t = scene.BallTruth(0);
  EXPECT_LT(t.cameras[0].visible_fraction, 0.3);
  EXPECT_GE(t.n_cams, 2);
}

// A seed gives the same scene whichever compiler built the presets: the random draws are
// sequenced (a call with two draws among its arguments gave clang another scene than GCC). The
// values are those written so far (GCC).
TEST(Presets, SeedGivesTheSameSceneWithEveryCompiler) {
  const auto near = [](const auto& a, const auto& b) { return (a - b).norm() < 1e-12; };
  const SceneSpec players = Preset("players", 3);
  EXPECT_TRUE(near(players.people[0].path.waypoints_m[0],
                   Eigen::Vector2d(-5.0342948084953907, -3.4471703742001134)));
  const SceneSpec kick = Preset("kick", 1);
  EXPECT_TRUE(near(kick.ball.kicks[0].position_m,
                   Eigen::Vector3d(-5.4309948279818911, -1.7996845500703711, 0.11)));
  EXPECT_TRUE(near(kick.ball.kicks[0].velocity_mps,
                   Eigen::Vector3d(5.342075985800518, 1.9140151990666268, 7.2847399676390214)));
  EXPECT_TRUE(
      near(kick.cones[0].position_m, Eigen::Vector2d(1.4995623581523885, -3.7876409430128004)));
  EXPECT_TRUE(near(Preset("static", 1).ball.placements[0],
                   Eigen::Vector3d(2.4747236545045355, -1.4930616729798791, 0.11)));
  EXPECT_TRUE(near(Preset("fisheye", 1).ball.placements[0],
                   Eigen::Vector3d(-8.5068468231817924, -5.9272754032203459, 0.9015161543524518)));
  EXPECT_TRUE(near(Preset("held", 1).robots[0].path.waypoints_m[0],
                   Eigen::Vector2d(3.829525155092746, -0.98216737223903605)));
}

TEST(Writer, ReproducibleFilesWithContractHeaders) {
  const uint64_t seed = fv::testing::TestSeed(9);
  FV_SEED_TRACE(seed);
  SceneSpec s = Preset("kick", seed);
  ResizeCameras(s, 160, 120);
  s.num_frames = 20;  // past the kick at 0.25 s
  s.people.push_back(PersonSpec{});
  s.people.back().path.waypoints_m = {Eigen::Vector2d(0, 0), Eigen::Vector2d(3, 1)};
  const std::string dir = fv::testing::TempDir();
  const WriteSceneResult a = WriteScene(s, dir + "/a");
  const WriteSceneResult b = WriteScene(s, dir + "/b");
  EXPECT_EQ(a.files.size(), b.files.size());
  for (const char* name : {"scene.json", "truth.csv", "truth_2d.csv", "flights.json", "cam1.yaml",
                           "cam1.avi", "players.csv", "players_2d.csv", "contact_sheet.png"}) {
    ASSERT_TRUE(fs::exists(dir + "/a/" + name)) << name;
    EXPECT_EQ(ReadAll(dir + "/a/" + name), ReadAll(dir + "/b/" + name)) << name;
  }
  EXPECT_EQ(util::CsvTable::Read(dir + "/a/truth.csv").header(),
            (std::vector<std::string>{"frame", "time_s", "x_m", "y_m", "z_m", "n_cams"}));
  EXPECT_EQ(util::CsvTable::Read(dir + "/a/truth.csv").rows(), 20u);
  EXPECT_EQ(
      util::CsvTable::Read(dir + "/a/truth_2d.csv").header(),
      (std::vector<std::string>{"frame", "cam", "u_px", "v_px", "radius_px", "visible_fraction"}));
  EXPECT_EQ(util::CsvTable::Read(dir + "/a/players.csv").header(),
            (std::vector<std::string>{"frame", "time_s", "id", "team", "x_m", "y_m"}));
  EXPECT_EQ(util::CsvTable::Read(dir + "/a/players_2d.csv").header(),
            (std::vector<std::string>{"frame", "cam", "id", "bb_left", "bb_top", "bb_width",
                                      "bb_height", "visible_fraction"}));
  const nlohmann::json flights = nlohmann::json::parse(ReadAll(dir + "/a/flights.json"));
  ASSERT_TRUE(flights.is_array());
  ASSERT_FALSE(flights.empty());
  for (const char* key : {"t_start_s", "t_end_s", "origin", "landing", "apex", "v0_mps"}) {
    EXPECT_TRUE(flights[0].contains(key)) << key;
  }
  // Camera files read back to the renderer's cameras.
  const SceneRenderer scene(s);
  const camera::Camera cam = camera::ReadCameraYaml(dir + "/a/cam2.yaml");
  const Eigen::Vector3d p(1, 2, 0.5);
  EXPECT_LT((*cam.Project(p) - *scene.cameras()[1].Project(p)).norm(), 1e-6);
  // Videos open with the right size and frame count.
  cv::VideoCapture cap(dir + "/a/cam3.avi");
  ASSERT_TRUE(cap.isOpened());
  int frames = 0;
  cv::Mat img;
  while (cap.read(img)) {
    EXPECT_EQ(img.cols, 160);
    EXPECT_EQ(img.rows, 120);
    ++frames;
  }
  EXPECT_EQ(frames, 20);
  // The spec written reads back to the same scene.
  EXPECT_EQ(SceneSpecToJson(ReadSceneSpec(dir + "/a/scene.json")).dump(),
            SceneSpecToJson(s).dump());
  // Another seed: other placements and noise.
  SceneSpec other = Preset("kick", seed + 1);
  ResizeCameras(other, 160, 120);
  other.num_frames = 6;
  EXPECT_NE(SceneSpecToJson(other).dump(), SceneSpecToJson(s).dump());
  SceneSpec noise_only = s;
  noise_only.seed = seed + 1;
  const SceneRenderer r1(s), r2(noise_only);
  const cv::Mat i1 = r1.RenderCamera(0, 1), i2 = r2.RenderCamera(0, 1);
  EXPECT_GT(cv::norm(i1, i2, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(i1, r1.RenderCamera(0, 1), cv::NORM_L1), 0.0);
}

// The first quantisation table (DQT, 64 values) of the first JPEG in `bytes`.
std::vector<int> FirstQuantTable(const std::string& bytes) {
  const size_t dqt = bytes.find("\xFF\xDB");
  if (dqt == std::string::npos || dqt + 5 + 64 > bytes.size()) return {};
  std::vector<int> q;
  for (size_t i = 0; i < 64; ++i) q.push_back(static_cast<unsigned char>(bytes[dqt + 5 + i]));
  return q;
}

TEST(Writer, MjpgFramesAreQuantisedAsTheSceneQualitySays) {
  // cv::imwrite's quality is libjpeg's; the scene's jpeg_quality means the same in its videos.
  SceneSpec s = CleanScene({Eigen::Vector3d(-2, -1, 0.5)}, 1);
  const std::string dir = fv::testing::TempDir();
  const cv::Mat grey(16, 16, CV_8UC3, cv::Scalar::all(128));
  for (const int quality : {50, 75, 90, 95}) {
    SCOPED_TRACE(quality);
    s.jpeg_quality = quality;
    WriteScene(s, dir + "/q");
    std::vector<uchar> jpg;
    cv::imencode(".jpg", grey, jpg, {cv::IMWRITE_JPEG_QUALITY, quality});
    const std::vector<int> want = FirstQuantTable(std::string(jpg.begin(), jpg.end()));
    const std::vector<int> got = FirstQuantTable(ReadAll(dir + "/q/a.avi"));
    ASSERT_EQ(got.size(), 64u);
    ASSERT_EQ(want.size(), 64u);
    // The same table up to rounding (OpenCV's writer rounds its own way).
    for (int i = 0; i < 64; ++i) EXPECT_NEAR(got[i], want[i], 1) << i;
  }
  // Beyond what that writer's tables reach: refused for videos, fine for image files.
  for (const int quality : {30, 97}) {
    s.format = "avi";
    s.jpeg_quality = quality;
    EXPECT_THAT([&] { s.Check(); }, ThrowsMessage<Error>(HasSubstr("jpeg_quality")));
    s.format = "jpg";
    EXPECT_NO_THROW(s.Check());
  }
}

TEST(Writer, ImageSequencesAndBadOutput) {
  SceneSpec s = CleanScene({Eigen::Vector3d(-2, -1, 0.5), Eigen::Vector3d(-1, 0, 1.0)}, 1);
  s.format = "png";
  const std::string dir = fv::testing::TempDir();
  WriteScene(s, dir + "/seq");
  EXPECT_TRUE(fs::exists(dir + "/seq/a/00000.png"));
  EXPECT_TRUE(fs::exists(dir + "/seq/b/00001.png"));
  cv::VideoCapture cap(dir + "/seq/a/%05d.png");
  ASSERT_TRUE(cap.isOpened());
  EXPECT_THROW(WriteScene(s, "/proc/nonexistent/x"), Error);
}

// "mp4": H.264 as OpenCV's FFmpeg writes it (where it has the encoder): every frame, each close to
// the scene's picture (the lossless PNG of the same frame), compressed.
TEST(Writer, Mp4IsH264OfEveryFrame) {
  const std::string dir = fv::testing::TempDir();
  {
    cv::VideoWriter probe(dir + "/probe.mp4", cv::CAP_FFMPEG,
                          cv::VideoWriter::fourcc('a', 'v', 'c', '1'), 30, cv::Size(64, 64));
    if (!probe.isOpened()) GTEST_SKIP() << "OpenCV's FFmpeg has no H.264 encoder here";
  }
  SceneSpec s = CleanScene(
      {Eigen::Vector3d(-2, -1, 0.5), Eigen::Vector3d(-1, 0, 1.0), Eigen::Vector3d(0, 1, 0.3)}, 1);
  s.format = "mp4";
  WriteScene(s, dir + "/mp4");
  s.format = "png";
  WriteScene(s, dir + "/png");
  cv::VideoCapture cap(dir + "/mp4/a.mp4");
  ASSERT_TRUE(cap.isOpened());
  cv::Mat frame;
  int n = 0;
  for (; cap.read(frame); ++n) {
    const cv::Mat png = cv::imread(fmt::format("{}/png/a/{:05d}.png", dir, n));
    ASSERT_EQ(frame.size(), png.size()) << n;
    const double mean_abs = cv::norm(frame, png, cv::NORM_L1) / (3.0 * png.total());
    EXPECT_LT(mean_abs, 8.0) << "frame " << n;  // the same picture
    EXPECT_GT(mean_abs, 0.0) << "frame " << n;  // compressed
  }
  EXPECT_EQ(n, s.num_frames);
  EXPECT_FALSE(fs::exists(dir + "/mp4/a.avi"));
}

TEST(Figures, PathsGoBackAndForth) {
  PathSpec p;
  p.waypoints_m = {Eigen::Vector2d(0, 0), Eigen::Vector2d(4, 0), Eigen::Vector2d(4, 3)};
  p.speeds_mps = {2.0, 1.0};
  p.speed_mps = 2.0;
  EXPECT_LT((PathAt(p, 1.0).position_m - Eigen::Vector2d(2, 0)).norm(), 1e-12);
  EXPECT_LT((PathAt(p, 3.0).position_m - Eigen::Vector2d(4, 1)).norm(), 1e-12);
  EXPECT_LT((PathAt(p, 5.0).position_m - Eigen::Vector2d(4, 3)).norm(), 1e-12);
  EXPECT_LT((PathAt(p, 6.0).position_m - Eigen::Vector2d(4, 2)).norm(), 1e-12);
  EXPECT_LT(PathAt(p, 6.0).heading.y(), 0);
  EXPECT_LT((PathAt(p, 10.0).position_m - Eigen::Vector2d(0, 0)).norm(), 1e-12);
  EXPECT_GT(PathAt(p, 6.0).gait_cycles, PathAt(p, 5.0).gait_cycles);
}

}  // namespace
}  // namespace fv::synth
