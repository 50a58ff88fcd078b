// The studio's HTTP API end to end: a server on a free loopback port over a folder holding a small
// synthetic scene, called with cpp-httplib's client. Every endpoint, and bad requests (unknown
// file, path outside the folder, malformed JSON, wrong method, missing token) get 4xx with a
// one-line message.
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>
#include <tuple>

#include <zmq.hpp>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <httplib.h>
// glibc's resolv.h (through httplib.h) defines _res, a parameter name in Eigen's headers.
#undef _res
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "fieldvision/calib/board_render.h"
#include "fieldvision/camera/camera_io.h"
#include "fieldvision/detect/colour.h"
#include "fieldvision/net/messages.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"
#include "fieldvision/web/studio_api.h"
#include "fieldvision/web/studio_server.h"

namespace fv::web {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

class StudioApiTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(fv::testing::TempDir()) / "work";
    fs::create_directories(dir_ / "scene");
    synth::SceneSpec spec = synth::Preset("static", seed_);
    synth::ResizeCameras(spec, 640, 480);
    spec.num_frames = 2;
    spec.cameras.resize(2);
    // Frame 0's ball rests within 2 m of the centre spot, 3-3.5 px in radius in cam1 (the preset
    // draws it anywhere on the field: 2.2 px at seed 22, too small to click around).
    util::Rng rng(seed_);
    spec.ball.placements[0].head<2>() =
        Eigen::Vector2d(rng.Uniform(-2.0, 2.0), rng.Uniform(-2.0, 2.0));
    spec.ball.placements[0].z() = spec.ball.radius_m();
    synth::WriteScene(spec, (dir_ / "scene").string());
    StartServer({});
  }

  void StartServer(StudioOptions o) {
    server_.reset();
    o.root = dir_.string();
#ifdef FV_PROGRAM
    o.program = FV_PROGRAM;
#endif
    o.port = 0;
    if (o.assets.empty()) o.assets = (dir_.parent_path() / "no-assets").string();
    server_ = std::make_unique<StudioServer>(o);
    port_ = server_->Start();
    client_ = std::make_unique<httplib::Client>("127.0.0.1", port_);
    client_->set_read_timeout(30);
  }

  struct Reply {
    int status = 0;
    std::string body;
    json j() const { return json::parse(body); }
  };
  Reply Get(const std::string& path, const httplib::Headers& headers = {}) {
    auto r = client_->Get(path.c_str(), headers);
    if (!r) return {-1, ""};
    return {r->status, r->body};
  }
  Reply Post(const std::string& path, const std::string& body) {
    auto r = client_->Post(path.c_str(), body, "application/json");
    if (!r) return {-1, ""};
    return {r->status, r->body};
  }
  Reply Post(const std::string& path, const json& body) { return Post(path, body.dump()); }

  // A 4xx reply whose body is {"error": one line}.
  static void ExpectError(const Reply& r, int status, const std::string& words) {
    EXPECT_EQ(r.status, status) << r.body;
    json j;
    ASSERT_NO_THROW(j = json::parse(r.body)) << r.body;
    ASSERT_TRUE(j.contains("error")) << r.body;
    const std::string e = j["error"];
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_NE(e.find(words), std::string::npos) << e;
  }

  // The truth camera's projections of the field keypoints it sees.
  json TruthKeypoints() {
    const Reply r = Post("/api/calibrate/project",
                         json{{"camera", "scene/cam1.yaml"}, {"field", "robocup-msl"}});
    EXPECT_EQ(r.status, 200) << r.body;
    return r.j()["keypoints_px"];
  }

  // The ball's truth in cam1 at frame 0 (truth_2d.csv).
  Eigen::Vector3d BallTruth() {
    const util::CsvTable t = util::CsvTable::Read((dir_ / "scene/truth_2d.csv").string());
    for (size_t i = 0; i < t.rows(); ++i) {
      if (t.GetInt(i, "frame") == 0 && t.Get(i, "cam") == "cam1") {
        return {t.GetDouble(i, "u_px"), t.GetDouble(i, "v_px"), t.GetDouble(i, "radius_px")};
      }
    }
    ADD_FAILURE() << "no ball truth for cam1";
    return Eigen::Vector3d::Zero();
  }

  // WALK.csv: player 3 walks along x at 1.5 m/s for 4 s (25 frames/s) from x = -2 m, through
  // the zone "strip" (strip.json, x from 1 to 2 m); player 4 stands still outside it.
  void WriteWalkAndStrip() {
    std::ofstream tracks(dir_ / "WALK.csv");
    tracks << "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s\n";
    for (int f = 0; f <= 100; ++f) {
      const double t = f / 25.0;
      tracks << fmt::format("{},3,0,0,10,20,1,{:.4f},0.5,{:.4f}\n", f + 1, 1.5 * t - 2.0, t);
      tracks << fmt::format("{},4,0,0,10,20,1,-5,-3,{:.4f}\n", f + 1, t);
    }
    tracks.close();
    const json zones = {{{"name", "strip"}, {"polygon", {{1, -1}, {2, -1}, {2, 1}, {1, 1}}}}};
    ASSERT_EQ(Post("/api/zones/save", json{{"zones", zones}, {"out", "strip.json"}}).status, 200);
  }

  uint64_t seed_ = fv::testing::TestSeed(1);
  fs::path dir_;
  std::unique_ptr<StudioServer> server_;
  std::unique_ptr<httplib::Client> client_;
  int port_ = 0;
};

TEST_F(StudioApiTest, InfoEndpointsAndFiles) {
  FV_SEED_TRACE(seed_);
  // The folder's field files are offered after the built-in fields; other JSON files are not.
  std::ofstream(dir_ / "pitch40.json") << R"({"name": "pitch40", "length_m": 40, "width_m": 20})";
  std::ofstream(dir_ / "other.json") << R"({"cameras": []})";
  const Reply info = Get("/api/info");
  ASSERT_EQ(info.status, 200);
  EXPECT_EQ(info.j()["root"], fs::canonical(dir_).string());
  const json fields = info.j()["fields"];
  EXPECT_EQ(fields.front(), "robocup-msl");
  EXPECT_EQ(fields.back(), "pitch40.json");
  EXPECT_EQ(info.body.find("other.json"), std::string::npos);
  const Reply endpoints = Get("/api/endpoints");
  ASSERT_EQ(endpoints.status, 200);
  EXPECT_EQ(endpoints.j().size(), StudioApi::Endpoints().size());
  // A lone numbered photo is an image (it was left out), a folder named build... is the user's
  // (only a CMake build tree is not listed).
  for (const char* folder : {"one", "buildings", "cmake-out", "seq", "photos"}) {
    fs::create_directories(dir_ / folder);
  }
  // Numbered frames in a row are a sequence; numbered photos with gaps are photos (a pattern over
  // the gaps opened none of them).
  for (const char* name : {"seq/00001.png", "seq/00002.png", "seq/00003.png", "photos/00005.jpg",
                           "photos/00006.jpg", "photos/00021.jpg"}) {
    cv::imwrite((dir_ / name).string(), cv::Mat(8, 8, CV_8UC3, cv::Scalar(9)));
  }
  cv::imwrite((dir_ / "one/00017.jpg").string(), cv::Mat(8, 8, CV_8UC3, cv::Scalar(0, 200, 255)));
  cv::imwrite((dir_ / "buildings/a.png").string(), cv::Mat(8, 8, CV_8UC3, cv::Scalar(9)));
  cv::imwrite((dir_ / "cmake-out/b.png").string(), cv::Mat(8, 8, CV_8UC3, cv::Scalar(9)));
  std::ofstream(dir_ / "cmake-out/CMakeCache.txt") << "# CMake\n";
  const Reply files = Get("/api/files");
  ASSERT_EQ(files.status, 200);
  std::map<std::string, std::string> kinds;
  for (const auto& f : files.j()) kinds[f["path"]] = f["kind"];
  EXPECT_EQ(kinds["scene/cam1.yaml"], "camera");
  EXPECT_EQ(kinds["scene/cam1.avi"], "video");
  EXPECT_EQ(kinds["scene/truth.csv"], "csv");
  EXPECT_EQ(kinds["one/00017.jpg"], "image");
  EXPECT_EQ(kinds["buildings/a.png"], "image");
  EXPECT_EQ(kinds.count("cmake-out/b.png"), 0u);
  EXPECT_EQ(kinds["seq/%05d.png"], "images");
  EXPECT_EQ(kinds["photos/00021.jpg"], "image");
  EXPECT_EQ(kinds.count("photos/%05d.jpg"), 0u);
  ExpectError(Get("/api/nothing"), 404, "unknown endpoint");
  ExpectError(Get("/nothing.html"), 404, "not found: /nothing.html");
  ExpectError(Post("/api/info", json::object()), 405, "not allowed");
  for (const auto& r :
       {client_->Put("/api/zones/save", "{}", "application/json"),
        client_->Patch("/api/info", "{}", "application/json"), client_->Delete("/api/info")}) {
    ASSERT_TRUE(r);
    ExpectError({r->status, r->body}, 405, "takes GET and POST");
  }
}

TEST_F(StudioApiTest, FieldVideoFrameAndCamera) {
  FV_SEED_TRACE(seed_);
  const Reply field = Get("/api/field?name=robocup-msl");
  ASSERT_EQ(field.status, 200);
  EXPECT_DOUBLE_EQ(field.j()["length_m"].get<double>(), 18.0);
  ExpectError(Get("/api/field?name=rugby"), 404, "unknown field");
  ExpectError(Get("/api/field"), 400, "missing query parameter 'name'");

  const Reply video = Get("/api/video?path=scene/cam1.avi");
  ASSERT_EQ(video.status, 200) << video.body;
  EXPECT_EQ(video.j()["width"], 640);
  EXPECT_EQ(video.j()["frames"], 2);

  auto frame = client_->Get("/api/frame?path=scene/cam1.avi&frame=1");
  ASSERT_TRUE(frame);
  ASSERT_EQ(frame->status, 200);
  EXPECT_EQ(frame->get_header_value("Content-Type"), "image/png");
  const std::vector<uchar> png(frame->body.begin(), frame->body.end());
  const cv::Mat image = cv::imdecode(png, cv::IMREAD_COLOR);
  EXPECT_EQ(image.cols, 640);
  EXPECT_EQ(image.rows, 480);
  ExpectError(Get("/api/frame?path=scene/cam1.avi&frame=5"), 422, "frame 5 does not exist");
  ExpectError(Get("/api/frame?path=scene/cam1.avi&frame=x"), 400, "not an integer");
  ExpectError(Get("/api/frame?path=scene/none.avi"), 404, "does not exist");

  const Reply cam = Get("/api/camera?path=scene/cam1.yaml");
  ASSERT_EQ(cam.status, 200);
  const camera::Camera truth = camera::ReadCameraYaml((dir_ / "scene/cam1.yaml").string());
  EXPECT_TRUE(cam.j()["has_pose"].get<bool>());
  EXPECT_NEAR(cam.j()["position_m"][0].get<double>(), truth.CentreInWorld().x(), 1e-9);
  // The image's border in normalized coordinates: 8 points a side from the top-left corner round,
  // each back at its place on the border through the lens.
  const json outline = cam.j()["image_outline_normalized"];
  ASSERT_EQ(outline.size(), 32u);
  const double w = truth.width - 0.5, h = truth.height - 0.5;
  const std::vector<Eigen::Vector2d> corners = {
      {-0.5, -0.5}, {w, -0.5}, {w, h}, {-0.5, h}, {-0.5, -0.5}};
  for (size_t i = 0; i < outline.size(); ++i) {
    const auto uv = truth.ProjectFromCamera(
        Eigen::Vector3d(outline[i][0].get<double>(), outline[i][1].get<double>(), 1.0));
    ASSERT_TRUE(uv.has_value());
    const double f = static_cast<double>(i % 8) / 8;
    const Eigen::Vector2d want = (1 - f) * corners[i / 8] + f * corners[i / 8 + 1];
    EXPECT_LT((*uv - want).norm(), 1e-6) << "outline point " << i << " at " << uv->transpose();
  }
  ExpectError(Get("/api/camera?path=scene/truth.csv"), 422, "truth.csv");
}

TEST_F(StudioApiTest, PathsOutsideTheFolderAreRefused) {
  FV_SEED_TRACE(seed_);
  std::ofstream(dir_.parent_path() / "secret.yaml") << "x: 1\n";
  ExpectError(Get("/api/camera?path=../secret.yaml"), 403, "outside the studio folder");
  ExpectError(Get("/api/camera?path=" + (dir_.parent_path() / "secret.yaml").string()), 403,
              "outside");
  ExpectError(Get("/api/json?path=/etc/hostname"), 403, "outside");
  ExpectError(Get("/api/frame?path=../../x/%2505d.png"), 403, "outside");
  fs::create_directory_symlink(dir_.parent_path(), dir_ / "link");
  ExpectError(Get("/api/camera?path=link/secret.yaml"), 403, "outside");
  // Writing outside: refused, nothing written.
  const json keypoints = TruthKeypoints();
  json points = json::array();
  for (const auto& k : keypoints) points.push_back(k);
  ExpectError(Post("/api/calibrate/save", json{{"camera", "scene/cam1.yaml"},
                                               {"field", "robocup-msl"},
                                               {"points", points},
                                               {"out", "../escaped.yaml"}}),
              403, "outside");
  EXPECT_FALSE(fs::exists(dir_.parent_path() / "escaped.yaml"));
  ExpectError(
      Post("/api/colour/save", json{{"range", {{"min", {0, 0, 0}}, {"max", {30, 255, 255}}}},
                                    {"out", "/tmp/fv-studio-escaped.json"}}),
      403, "outside");
  EXPECT_FALSE(fs::exists("/tmp/fv-studio-escaped.json"));
  ExpectError(
      Post("/api/colour/save", json{{"range", {{"min", {0, 0, 0}}, {"max", {30, 255, 255}}}},
                                    {"out", "nofolder/c.json"}}),
      404, "does not exist");
}

// Each endpoint that reads a file: no path (400), a missing file (404), a path outside (403);
// each POST endpoint: malformed JSON (400). One line each.
TEST_F(StudioApiTest, EveryEndpointRefusesBadFilesAndMalformedJson) {
  FV_SEED_TRACE(seed_);
  for (const std::string get : {"/api/video?", "/api/frame?frame=0&", "/api/camera?", "/api/ball?",
                                "/api/tracks?", "/api/zones?", "/api/json?"}) {
    SCOPED_TRACE(get);
    ExpectError(Get(get), 400, "missing query parameter 'path'");
    ExpectError(Get(get + "path=missing.csv"), 404, "missing.csv");
    ExpectError(Get(get + "path=../x.csv"), 403, "outside");
  }
  const json uv = json::array({json::array({10, 10})});
  for (const auto& [path, key, body] : std::vector<std::tuple<std::string, std::string, json>>{
           {"/api/calibrate/project", "camera", {{"field", "robocup-msl"}}},
           {"/api/calibrate/pose", "camera", {{"field", "robocup-msl"}, {"points", json::array()}}},
           {"/api/colour/learn", "video", {{"frame", 0}, {"points", uv}}},
           {"/api/colour/detect", "video", {{"frames", {0}}}},
           {"/api/players/stats", "tracks", json::object()},
           {"/api/players/export", "tracks", {{"out", "export"}}}}) {
    SCOPED_TRACE(path);
    json missing = body;
    missing[key] = "missing.file";
    ExpectError(Post(path, missing), 404, "missing.file");
    json outside = body;
    outside[key] = "../x.file";
    ExpectError(Post(path, outside), 403, "outside");
  }
  for (const auto& e : StudioApi::Endpoints()) {
    if (e.method != "POST") continue;
    SCOPED_TRACE(e.path);
    ExpectError(Post(e.path, std::string("{\"out\": ")), 400, "malformed JSON");
    // A number too large for a double: the same, without nlohmann's "[json.exception..." tag.
    const Reply huge = Post(e.path, std::string("{\"frame\": 1e400}"));
    ExpectError(huge, 400, "malformed JSON");
    EXPECT_EQ(huge.body.find("json.exception"), std::string::npos) << huge.body;
    // Nested a million levels deep: copying or dumping it would overflow the server's stack.
    const std::string deep =
        "{\"zones\": " + std::string(1000000, '[') + std::string(1000000, ']') + "}";
    ExpectError(Post(e.path, deep), 400, "deeper than");
  }
  EXPECT_EQ(Get("/api/info").status, 200);  // the server still answers
}

TEST_F(StudioApiTest, MalformedRequests) {
  FV_SEED_TRACE(seed_);
  ExpectError(Post("/api/calibrate/pose", std::string("{not json")), 400, "malformed JSON");
  // Another origin's page: a plain-text POST (no CORS preflight), or a rebound host name.
  auto text =
      client_->Post("/api/colour/save", R"({"range":{"min":[0,0,0],"max":[9,9,9]},"out":"x.json"})",
                    "text/plain");
  ASSERT_TRUE(text);
  ExpectError({text->status, text->body}, 415, "application/json");
  EXPECT_FALSE(fs::exists(dir_ / "x.json"));
  ExpectError(Get("/api/info", {{"Host", "evil.example:8470"}}), 403, "loopback host");
  // A name that merely begins like a loopback address resolves wherever its owner says.
  ExpectError(Get("/api/info", {{"Host", "127.attacker.example:8470"}}), 403, "loopback host");
  EXPECT_EQ(Get("/api/info", {{"Host", "127.0.0.1:8470"}}).status, 200);
  EXPECT_EQ(Get("/api/info", {{"Host", "localhost:8470"}}).status, 200);
  EXPECT_EQ(Get("/api/info", {{"Host", "[::1]:8470"}}).status, 200);
  ExpectError(Post("/api/calibrate/pose", std::string("")), 400, "empty");
  // A key with bytes that are not UTF-8 is named in the error (replaced), never thrown on.
  const Reply bad_utf8 = Post("/api/calibrate/pose",
                              std::string("{\"camera\": \"cam.yaml\", \"points\xff\xff|\": 1}"));
  EXPECT_GE(bad_utf8.status, 400);
  EXPECT_LT(bad_utf8.status, 500);
  EXPECT_NO_THROW(json::parse(bad_utf8.body)) << bad_utf8.body;
  ExpectError(Post("/api/calibrate/pose", std::string("[1, 2]")), 400, "not a JSON object");
  ExpectError(Post("/api/calibrate/pose", json{{"camera", 3}}), 400, "wrong type");
  ExpectError(
      Post("/api/calibrate/pose", json{{"camera", "scene/cam1.yaml"}, {"field", "robocup-msl"}}),
      400, "points");
  ExpectError(
      Post("/api/calibrate/pose", json{{"camera", "scene/cam1.yaml"},
                                       {"field", "robocup-msl"},
                                       {"points", {{{"name", "nowhere"}, {"u", 1}, {"v", 2}}}}}),
      400, "not a keypoint");
  ExpectError(Post("/api/colour/learn", json{{"video", "scene/cam1.avi"}}), 400, "points");
  ExpectError(
      Post("/api/colour/detect", json{{"video", "scene/cam1.avi"}, {"frames", json::array()}}), 400,
      "frames");
  // Numbers that are no int (frame 2^32 + 5 read as 5, 5.9 as 5, a box of 1e12 as INT_MIN).
  for (const json& frames : {json{4294967301LL}, json{5.9}}) {
    ExpectError(Post("/api/colour/detect", json{{"video", "scene/cam1.avi"}, {"frames", frames}}),
                400, "key 'frames' must hold integers in range");
  }
  ExpectError(Post("/api/colour/save", json{{"range", {{"min", {0, 0}}}}, {"out", "c.json"}}), 400,
              "range");
}

TEST_F(StudioApiTest, PoseFromClickedKeypoints) {
  FV_SEED_TRACE(seed_);
  const json keypoints = TruthKeypoints();
  ASSERT_GE(keypoints.size(), 6u);
  json points = json::array();
  for (size_t i = 0; i < 3; ++i) points.push_back(keypoints[i]);
  json body = {{"camera", "scene/cam1.yaml"}, {"field", "robocup-msl"}, {"points", points}};
  ExpectError(Post("/api/calibrate/pose", body), 422, "");  // too few points: the library says
  for (size_t i = 3; i < keypoints.size(); ++i) points.push_back(keypoints[i]);
  body["points"] = points;
  const Reply pose = Post("/api/calibrate/pose", body);
  ASSERT_EQ(pose.status, 200) << pose.body;
  const camera::Camera truth = camera::ReadCameraYaml((dir_ / "scene/cam1.yaml").string());
  const json j = pose.j();
  const Eigen::Vector3d position(j["camera_position_m"][0], j["camera_position_m"][1],
                                 j["camera_position_m"][2]);
  EXPECT_LT((position - truth.CentreInWorld()).norm(), 0.005);
  EXPECT_LT(j["rms_px"].get<double>(), 0.01);
  EXPECT_EQ(j["points"].size(), points.size());
  EXPECT_FALSE(j["lines_px"].empty());

  body["out"] = "scene/cam1_studio.yaml";
  body["points_out"] = "scene/cam1_points.csv";
  const Reply saved = Post("/api/calibrate/save", body);
  ASSERT_EQ(saved.status, 200) << saved.body;
  const camera::Camera written = camera::ReadCameraYaml((dir_ / "scene/cam1_studio.yaml").string());
  EXPECT_LT((written.CentreInWorld() - truth.CentreInWorld()).norm(), 0.005);
  EXPECT_EQ(util::CsvTable::Read((dir_ / "scene/cam1_points.csv").string()).rows(), points.size());
  // Saving over the camera calibrated from (or any file there) waits for replace: the page asks.
  const auto size_before = fs::file_size(dir_ / "scene/cam1.yaml");
  body["out"] = "scene/cam1.yaml";
  body.erase("points_out");
  ExpectError(Post("/api/calibrate/save", body), 409, "'scene/cam1.yaml' exists");
  EXPECT_EQ(fs::file_size(dir_ / "scene/cam1.yaml"), size_before);
  body["replace"] = true;
  EXPECT_EQ(Post("/api/calibrate/save", body).status, 200);
}

TEST_F(StudioApiTest, PoseRefinedAgainstThePaintedLines) {
  FV_SEED_TRACE(seed_);
  // cam1 moved 12 cm and turned 0.4 degrees off the truth: the lines of its frame pull it back.
  const camera::Camera truth = camera::ReadCameraYaml((dir_ / "scene/cam1.yaml").string());
  camera::Camera off = truth;
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.4 * M_PI / 180, Eigen::Vector3d(1, 2, 0.5).normalized()).matrix();
  off.cam_from_world.rotation = turn * truth.cam_from_world.rotation;
  off.cam_from_world.translation = turn * truth.cam_from_world.translation;
  off.cam_from_world.translation +=
      off.cam_from_world.rotation * Eigen::Vector3d(0.08, -0.06, 0.06);
  camera::WriteCameraYaml(off, (dir_ / "scene/cam1_off.yaml").string());
  const double before_m = (off.CentreInWorld() - truth.CentreInWorld()).norm();

  json body = {{"camera", "scene/cam1_off.yaml"},
               {"field", "robocup-msl"},
               {"video", "scene/cam1.avi"},
               {"frame", 0},
               {"out", "scene/cam1_refined.yaml"}};
  const Reply r = Post("/api/calibrate/refine", body);
  ASSERT_EQ(r.status, 200) << r.body;
  const json j = r.j();
  EXPECT_TRUE(j["accepted"].get<bool>()) << j["summary"];
  EXPECT_GT(j["num_line_pixels"].get<int>(), 100);
  EXPECT_FALSE(j["line_pixels"].empty());
  EXPECT_FALSE(j["lines_px"].empty());
  EXPECT_LT(j["after"]["mean_mm"].get<double>(), 0.5 * j["before"]["mean_mm"].get<double>())
      << j["summary"];
  const camera::Camera refined =
      camera::ReadCameraYaml((dir_ / "scene/cam1_refined.yaml").string());
  const double after_m = (refined.CentreInWorld() - truth.CentreInWorld()).norm();
  EXPECT_LT(after_m, 0.3 * before_m) << "before " << before_m << " m, after " << after_m << " m";
  EXPECT_EQ(j["wrote"][0], "scene/cam1_refined.yaml");

  // Starting from clicked points instead of the file's pose (cam1's intrinsics file has one too).
  json points = json::array();
  for (const auto& k : TruthKeypoints()) points.push_back(k);
  body["camera"] = "scene/cam1_off.yaml";
  body["points"] = points;
  body.erase("out");
  const Reply from_clicks = Post("/api/calibrate/refine", body);
  ASSERT_EQ(from_clicks.status, 200) << from_clicks.body;
  EXPECT_TRUE(from_clicks.j()["wrote"].empty());

  // Bad requests.
  camera::Camera no_pose = truth;
  no_pose.has_pose = false;
  camera::WriteCameraYaml(no_pose, (dir_ / "scene/cam1_intrinsics.yaml").string());
  body = {{"camera", "scene/cam1_intrinsics.yaml"},
          {"field", "robocup-msl"},
          {"video", "scene/cam1.avi"}};
  ExpectError(Post("/api/calibrate/refine", body), 422, "no pose to refine");
  body["camera"] = "scene/cam1.yaml";
  body["video"] = "scene/nothing.avi";
  ExpectError(Post("/api/calibrate/refine", body), 404, "nothing.avi");
  body["video"] = "scene/cam1.avi";
  body["out"] = "../escape.yaml";
  ExpectError(Post("/api/calibrate/refine", body), 403, "");
  EXPECT_FALSE(fs::exists(dir_.parent_path() / "escape.yaml"));
  camera::Camera small = truth;
  small.width = 320;
  small.height = 240;
  camera::WriteCameraYaml(small, (dir_ / "scene/small.yaml").string());
  body = {{"camera", "scene/small.yaml"}, {"field", "robocup-msl"}, {"video", "scene/cam1.avi"}};
  ExpectError(Post("/api/calibrate/refine", body), 422, "");
}

TEST_F(StudioApiTest, IntrinsicsFromBoardImagesWithPerViewErrors) {
  FV_SEED_TRACE(seed_);
  // Eight views of a 9x6 chessboard (25 mm) seen by a 640x480 camera, fx = fy = 600.
  camera::Camera cam;
  cam.width = 640;
  cam.height = 480;
  cam.fx = cam.fy = 600;
  cam.cx = 322;
  cam.cy = 238;
  cam.distortion = {0, 0, 0, 0, 0};
  calib::BoardSpec board;
  const calib::BoardPicture picture = calib::DrawBoard(board, 3000);
  fs::create_directories(dir_ / "boards");
  util::Rng rng(seed_);
  const Eigen::Vector3d centre((board.cols - 1) * board.square_m / 2,
                               (board.rows - 1) * board.square_m / 2, 0);
  for (int i = 0; i < 8; ++i) {
    const double ax = rng.Uniform(-0.5, 0.5), ay = rng.Uniform(-0.5, 0.5);
    geometry::Rigid3d cam_from_board;
    cam_from_board.rotation = (Eigen::AngleAxisd(ax, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(ay, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(rng.Uniform(-0.3, 0.3), Eigen::Vector3d::UnitZ()))
                                  .matrix();
    const Eigen::Vector3d at(rng.Uniform(-0.06, 0.06), rng.Uniform(-0.04, 0.04),
                             rng.Uniform(0.38, 0.5));
    cam_from_board.translation = at - cam_from_board.rotation * centre;
    cv::imwrite((dir_ / "boards" / fmt::format("view{:02d}.png", i)).string(),
                calib::RenderBoardView(picture, cam, cam_from_board));
  }
  const json chessboard = {{"type", "chessboard"}, {"cols", 9}, {"rows", 6}, {"square_m", 0.025}};
  json body = {{"images", "boards/*.png"},
               {"board", chessboard},
               {"num_distortion", 4},
               {"name", "studio_cam"},
               {"out", "boards/cam.yaml"}};
  const Reply r = Post("/api/calibrate/intrinsics", body);
  ASSERT_EQ(r.status, 200) << r.body;
  const json j = r.j();
  EXPECT_NEAR(j["camera"]["fx"].get<double>(), 600, 6) << j["summary"];
  EXPECT_NEAR(j["camera"]["fy"].get<double>(), 600, 6);
  EXPECT_NEAR(j["camera"]["cx"].get<double>(), 322, 6);
  EXPECT_NEAR(j["camera"]["cy"].get<double>(), 238, 6);
  ASSERT_EQ(j["views"].size(), 8u);
  for (const auto& v : j["views"]) {
    EXPECT_TRUE(v["board_found"].get<bool>()) << v["name"];
    EXPECT_EQ(v["num_corners"], 54);
    EXPECT_LT(v["rms_px"].get<double>(), 0.5) << v["name"];
    EXPECT_EQ(v["name"].get<std::string>().rfind("boards/view", 0), 0u) << v["name"];
  }
  EXPECT_EQ(j["num_used"], 8);
  EXPECT_EQ(j["wrote"][0], "boards/cam.yaml");
  const camera::Camera written = camera::ReadCameraYaml((dir_ / "boards/cam.yaml").string());
  EXPECT_NEAR(written.fx, j["camera"]["fx"].get<double>(), 1e-3);
  EXPECT_EQ(written.name, "studio_cam");

  // Bad requests: images outside, wildcards in a folder name, a bad board, no board found, a k3
  // model that is not one or not a string.
  body.erase("out");
  body["images"] = "../*.png";
  ExpectError(Post("/api/calibrate/intrinsics", body), 403, "");
  body["images"] = "b*/view00.png";
  ExpectError(Post("/api/calibrate/intrinsics", body), 400, "wildcards");
  body["images"] = "boards/*.png";
  body["board"]["cols"] = 1;
  ExpectError(Post("/api/calibrate/intrinsics", body), 400, "");
  body["board"] = {{"type", "chessboard"}, {"cols", 7}, {"rows", 5}, {"square_m", 0.025}};
  ExpectError(Post("/api/calibrate/intrinsics", body), 422, "");
  body["board"] = "chessboard";
  ExpectError(Post("/api/calibrate/intrinsics", body), 400, "board");
  body["board"] = chessboard;
  body["k3"] = "maybe";
  ExpectError(Post("/api/calibrate/intrinsics", body), 400, "k3");
  body["k3"] = 5;
  ExpectError(Post("/api/calibrate/intrinsics", body), 400, "k3");
}

TEST_F(StudioApiTest, LivePositionsFromAFusionNodeArriveAsEvents) {
  // A PUB socket as `fuse --publish` binds it, sending ball messages (net/messages.h).
  zmq::context_t ctx(1);
  zmq::socket_t pub(ctx, zmq::socket_type::pub);
  pub.set(zmq::sockopt::linger, 0);
  pub.bind("tcp://127.0.0.1:*");
  const std::string endpoint = pub.get(zmq::sockopt::last_endpoint);

  ExpectError(Post("/api/live/start", json{{"endpoint", "ipc:///etc/passwd"}}), 400, "tcp://");
  ExpectError(Post("/api/live/start", json{{"endpoint", "tcp://127.0.0.1"}}), 400, "tcp://");
  // As the commands' --connect: a port past 65535 is no address (it was accepted, "running").
  ExpectError(Post("/api/live/start", json{{"endpoint", "tcp://256.1.1.1:99999"}}), 400,
              "PORT 1..65535");
  ExpectError(Post("/api/live/start", json::object()), 400, "endpoint");
  EXPECT_EQ(Get("/api/live").j()["state"], "idle");

  // The event stream, read on a thread of its own.
  std::mutex mutex;
  std::string stream;
  std::atomic<bool> done{false};
  httplib::Client events("127.0.0.1", port_);
  events.set_read_timeout(20);
  std::thread reader([&] {
    events.Get("/api/events", [&](const char* data, size_t n) {
      std::lock_guard<std::mutex> lock(mutex);
      stream.append(data, n);
      return !done && stream.find("\"frame\":7") == std::string::npos;
    });
  });
  for (int i = 0; i < 200; ++i) {  // the stream is open once its hello has come
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (stream.find("event: hello") != std::string::npos) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const Reply start = Post("/api/live/start", json{{"endpoint", endpoint}});
  ASSERT_EQ(start.status, 200) << start.body;
  EXPECT_EQ(start.j()["state"], "running");

  // ZeroMQ subscriptions take a moment to reach the publisher: publish until seen.
  int received = 0;
  for (int i = 0; i < 400 && received < 3; ++i) {
    net::BallMessage b;
    b.frame = i;
    b.time_s = i / 30.0;
    b.x_m = 1.5;
    b.y_m = -2.0;
    b.z_m = 0.25 + 0.01 * i;
    b.n_cams = 3;
    b.err_px = 0.4;
    pub.send(zmq::buffer(std::string("ball")), zmq::send_flags::sndmore);
    pub.send(zmq::buffer(net::Encode(b)));
    if (i == 2) {  // a malformed message is counted and skipped
      pub.send(zmq::buffer(std::string("ball")), zmq::send_flags::sndmore);
      pub.send(zmq::buffer(std::string("{not json")));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    received = Get("/api/live").j()["received"].get<int>();
  }
  ASSERT_GE(received, 3);
  const json status = Get("/api/live").j();
  EXPECT_EQ(status["endpoint"], endpoint);
  EXPECT_DOUBLE_EQ(status["last"]["x_m"].get<double>(), 1.5);
  EXPECT_EQ(status["last"]["n_cams"], 3);

  // Keep publishing until the stream has frame 7 (or give up after 20 s).
  for (int i = 0; i < 400; ++i) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (stream.find("\"frame\":7") != std::string::npos) break;
    }
    net::BallMessage b;
    b.frame = 7;
    b.x_m = 1.5;
    pub.send(zmq::buffer(std::string("ball")), zmq::send_flags::sndmore);
    pub.send(zmq::buffer(net::Encode(b)));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const Reply stop = Post("/api/live/stop", json::object());
  ASSERT_EQ(stop.status, 200) << stop.body;
  EXPECT_EQ(stop.j()["state"], "idle");
  done = true;
  reader.join();
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_NE(stream.find("event: live"), std::string::npos) << stream;
  EXPECT_NE(stream.find("event: ball"), std::string::npos) << stream;
  EXPECT_NE(stream.find("\"frame\":7"), std::string::npos) << stream;
}

TEST_F(StudioApiTest, LiveFeedFromTheStart) {
  StudioOptions bad;
  bad.live = "ipc:///tmp/x";
  EXPECT_THROW(bad.Check(), fv::Error);
  StudioOptions o;
  o.live = "tcp://127.0.0.1:5999";  // nothing there yet: ZeroMQ connects when it comes
  StartServer(o);
  const json status = Get("/api/live").j();
  EXPECT_EQ(status["state"], "running");
  EXPECT_EQ(status["endpoint"], "tcp://127.0.0.1:5999");
}

TEST_F(StudioApiTest, BallColourLearnSaveDetect) {
  FV_SEED_TRACE(seed_);
  const Eigen::Vector3d ball = BallTruth();
  ASSERT_GT(ball.z(), 2.5) << "ball too small in the test scene";
  const double r = 0.5 * ball.z();
  json points = {{ball.x(), ball.y()},
                 {ball.x() + r, ball.y()},
                 {ball.x() - r, ball.y()},
                 {ball.x(), ball.y() + r},
                 {ball.x(), ball.y() - r}};
  const Reply learned = Post("/api/colour/learn",
                             json{{"video", "scene/cam1.avi"}, {"frame", 0}, {"points", points}});
  ASSERT_EQ(learned.status, 200) << learned.body;
  EXPECT_GT(learned.j()["recall"].get<double>(), 0.8);
  EXPECT_EQ(learned.j()["frames"], 1);
  const json range = learned.j()["range"];
  // Clicks on several frames are learned together; a frame without clicks is named.
  const json sample = {{"frame", 0}, {"points", points}};
  const Reply pooled =
      Post("/api/colour/learn", json{{"video", "scene/cam1.avi"}, {"samples", {sample, sample}}});
  ASSERT_EQ(pooled.status, 200) << pooled.body;
  EXPECT_EQ(pooled.j()["frames"], 2);
  EXPECT_EQ(pooled.j()["positives"].get<int>(), 2 * learned.j()["positives"].get<int>());
  EXPECT_EQ(pooled.j()["range"], range);
  ExpectError(Post("/api/colour/learn",
                   json{{"video", "scene/cam1.avi"}, {"samples", {sample, {{"frame", 1}}}}}),
              400, "samples[1]: give 'points' or 'roi'");
  ExpectError(
      Post("/api/colour/learn", json{{"video", "scene/cam1.avi"}, {"samples", json::array()}}), 400,
      "'samples' must be an array");

  const Reply saved = Post("/api/colour/save", json{{"range", range}, {"out", "ball.json"}});
  ASSERT_EQ(saved.status, 200) << saved.body;
  EXPECT_NO_THROW(detect::ReadColourSpec((dir_ / "ball.json").string()));

  const Reply det = Post("/api/colour/detect", json{{"video", "scene/cam1.avi"},
                                                    {"frames", {0, 1}},
                                                    {"colour", "ball.json"},
                                                    {"camera", "scene/cam1.yaml"}});
  ASSERT_EQ(det.status, 200) << det.body;
  const json f0 = det.j()["frames"][0];
  ASSERT_FALSE(f0["candidates"].empty()) << det.body;
  const json best = f0["candidates"][0];
  EXPECT_TRUE(best["accepted"].get<bool>()) << best.dump();
  EXPECT_LT(std::hypot(best["u"].get<double>() - ball.x(), best["v"].get<double>() - ball.y()),
            1.5);
  ExpectError(
      Post("/api/colour/detect", json{{"video", "scene/cam1.avi"}, {"colour", "missing.json"}}),
      404, "missing.json");
}

TEST_F(StudioApiTest, BallTracksFlightsAndPlayers) {
  FV_SEED_TRACE(seed_);
  std::ofstream(dir_ / "BALL.csv") << "frame,time_s,x_m,y_m,z_m,n_cams,err_px\n"
                                      "0,0,1,2,0.11,2,0.5\n1,0.02,1.1,2,0.3,3,0.4\n";
  const Reply ball = Get("/api/ball?path=BALL.csv");
  ASSERT_EQ(ball.status, 200) << ball.body;
  ASSERT_EQ(ball.j()["samples"].size(), 2u);
  EXPECT_DOUBLE_EQ(ball.j()["samples"][1][2].get<double>(), 1.1);
  ExpectError(Get("/api/ball?path=scene/cam1.yaml"), 422, "cam1.yaml");

  const Reply flights = Get("/api/json?path=scene/flights.json");
  ASSERT_EQ(flights.status, 200) << flights.body;
  std::ofstream(dir_ / "bad.json") << "{oops";
  ExpectError(Get("/api/json?path=bad.json"), 422, "not valid JSON");

  std::ofstream(dir_ / "TRACKS.csv")
      << "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s\n"
         "1,7,10,20,30,60,0.9,1.5,-2,0\n2,7,11,20,30,60,0.9,,,0.04\n";
  const Reply tracks = Get("/api/tracks?path=TRACKS.csv");
  ASSERT_EQ(tracks.status, 200) << tracks.body;
  const json rows = tracks.j()["rows"];
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0][1], 7);
  EXPECT_DOUBLE_EQ(rows[0][6].get<double>(), 1.5);
  EXPECT_TRUE(rows[1][6].is_null());
  EXPECT_TRUE(rows[0][9].is_null());  // no team column
  std::ofstream(dir_ / "TEAMS.csv")
      << "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s,team\n"
         "1,7,10,20,30,60,0.9,1.5,-2,0,1\n";
  const Reply teams = Get("/api/tracks?path=TEAMS.csv");
  ASSERT_EQ(teams.status, 200) << teams.body;
  EXPECT_EQ(teams.j()["rows"][0][9], 1);
  ExpectError(Get("/api/tracks?path=scene/truth.csv"), 422, "truth.csv");
}

TEST_F(StudioApiTest, PlayerStatsAndZoneAlerts) {
  ASSERT_NO_FATAL_FAILURE(WriteWalkAndStrip());  // player 3 walks through "strip", 4 stands
  const Reply r = Post("/api/players/stats", json{{"tracks", "WALK.csv"}, {"zones", "strip.json"}});
  ASSERT_EQ(r.status, 200) << r.body;
  const json j = r.j();
  ASSERT_EQ(j["players"].size(), 2u) << r.body;
  for (const auto& p : j["players"]) {
    if (p["id"] == 3) {
      EXPECT_NEAR(p["distance_m"].get<double>(), 6.0, 0.1);
      EXPECT_NEAR(p["top_speed_mps"].get<double>(), 1.5, 0.05);
      EXPECT_NEAR(p["zone_time_s"]["strip"].get<double>(), 1.0 / 1.5, 0.1);
    } else {
      EXPECT_LT(p["distance_m"].get<double>(), 0.01);
    }
  }
  ASSERT_EQ(j["events"].size(), 1u) << r.body;
  EXPECT_EQ(j["events"][0]["id"], 3);
  EXPECT_EQ(j["events"][0]["zone"], "strip");
  EXPECT_NEAR(j["events"][0]["enter_s"].get<double>(), 2.0, 0.05);  // x = 1 m at t = 2 s
  EXPECT_NEAR(j["events"][0]["exit_s"].get<double>(), 2.0 + 1.0 / 1.5, 0.05);
  // Without zones; a file that is not a tracks file; a zones file that is not one.
  const Reply plain = Post("/api/players/stats", json{{"tracks", "WALK.csv"}});
  ASSERT_EQ(plain.status, 200) << plain.body;
  EXPECT_TRUE(plain.j()["events"].empty());
  for (const auto& p : plain.j()["players"]) EXPECT_EQ(p["team"], -1);
  // The teams `players` wrote beside the tracks, as `stats` takes them (they were left out:
  // the page showed teams, the exported players.csv -1).
  std::ofstream(dir_ / "WALK.csv.teams.csv") << "id,team,name\n3,1,Ann\n";
  const Reply teams = Post("/api/players/stats", json{{"tracks", "WALK.csv"}});
  ASSERT_EQ(teams.status, 200) << teams.body;
  for (const auto& p : teams.j()["players"]) EXPECT_EQ(p["team"], p["id"] == 3 ? 1 : -1);
  for (const auto& row : Get("/api/tracks?path=WALK.csv").j()["rows"]) {
    EXPECT_EQ(row[9], row[1] == 3 ? json(1) : json(nullptr));
  }
  fs::remove(dir_ / "WALK.csv.teams.csv");
  ExpectError(Post("/api/players/stats", json{{"tracks", "scene/cam1.yaml"}}), 422, "cam1.yaml");
  ExpectError(Post("/api/players/stats", json{{"tracks", "WALK.csv"}, {"zones", "WALK.csv"}}), 422,
              "WALK.csv");
  ExpectError(Post("/api/players/stats", json{{"tracks", "../WALK.csv"}}), 403, "");
}

std::string Base64(const std::string& bytes) {
  static const char* const kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t v = 0;
    for (size_t k = 0; k < 3; ++k) v = (v << 8) | (k < n ? static_cast<uint8_t>(bytes[i + k]) : 0);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

TEST_F(StudioApiTest, PlayersExport) {
  ASSERT_NO_FATAL_FAILURE(WriteWalkAndStrip());
  // The page's heat map as a canvas sends it (a data: URL).
  cv::Mat heat(30, 50, CV_8UC4, cv::Scalar(10, 200, 30, 255));
  std::vector<uchar> png;
  cv::imencode(".png", heat, png);
  const std::string heat_url =
      "data:image/png;base64," + Base64(std::string(png.begin(), png.end()));
  json request = {{"tracks", "WALK.csv"},
                  {"zones", "strip.json"},
                  {"field", "robocup-msl"},
                  {"images", {{"heatmap", heat_url}}},
                  {"out", "exports/walk"}};
  ExpectError(Post("/api/players/export", request), 404, "does not exist");  // no exports/
  fs::create_directory(dir_ / "exports");
  // A link already in the folder is replaced, not written through.
  fs::create_directory(dir_ / "exports/walk");
  std::ofstream(dir_.parent_path() / "victim.csv") << "untouched\n";
  fs::create_symlink(dir_.parent_path() / "victim.csv", dir_ / "exports/walk/players.csv");
  // A folder that is not empty is refused unless replaced; then an earlier export's files go
  // (a player's map of the last export among them), the user's own stay.
  std::ofstream(dir_ / "exports/walk/heatmap_player9.png") << "an earlier export's player 9\n";
  std::ofstream(dir_ / "exports/walk/notes.txt") << "the user's\n";
  ExpectError(Post("/api/players/export", request), 409, "replace: true");
  EXPECT_TRUE(fs::exists(dir_ / "exports/walk/heatmap_player9.png"));
  request["replace"] = true;
  const Reply r = Post("/api/players/export", request);
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_FALSE(fs::exists(dir_ / "exports/walk/heatmap_player9.png"));
  EXPECT_TRUE(fs::exists(dir_ / "exports/walk/notes.txt"));
  std::set<std::string> wrote;
  const json reply = r.j();
  for (const auto& w : reply["wrote"]) wrote.insert(w.get<std::string>());
  for (const char* f :
       {"players.csv", "speed_profiles.csv", "distances.csv", "zone_alerts.csv", "heatmap_all.png",
        "radar.png", "stats.json", "index.html", "page_heatmap.png"}) {
    EXPECT_TRUE(wrote.count(std::string("exports/walk/") + f)) << f << ": " << r.body;
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir_ / "exports/walk" / f))) << f;
  }
  {
    std::ifstream victim(dir_.parent_path() / "victim.csv");
    std::string line;
    std::getline(victim, line);
    EXPECT_EQ(line, "untouched");
  }
  for (const auto& e : fs::directory_iterator(dir_ / "exports")) {
    EXPECT_EQ(e.path().filename(), "walk") << "left behind: " << e.path();
  }
  // The statistics are the library's (as /api/players/stats), the alerts one row per stay.
  const util::CsvTable players = util::CsvTable::Read((dir_ / "exports/walk/players.csv").string());
  ASSERT_EQ(players.rows(), 2u);
  for (size_t i = 0; i < players.rows(); ++i) {
    if (players.GetInt(i, "id") == 3) {
      EXPECT_NEAR(players.GetDouble(i, "distance_m"), 6.0, 0.1);
      EXPECT_NEAR(players.GetDouble(i, "time_in_strip_s"), 1.0 / 1.5, 0.1);
    }
  }
  const util::CsvTable alerts =
      util::CsvTable::Read((dir_ / "exports/walk/zone_alerts.csv").string());
  ASSERT_EQ(alerts.rows(), 1u);
  EXPECT_EQ(alerts.Get(0, "zone"), "strip");
  EXPECT_EQ(alerts.GetInt(0, "id"), 3);
  EXPECT_NEAR(alerts.GetDouble(0, "enter_s"), 2.0, 0.05);
  const cv::Mat page = cv::imread((dir_ / "exports/walk/page_heatmap.png").string(), -1);
  ASSERT_FALSE(page.empty());
  EXPECT_EQ(page.size(), heat.size());
  EXPECT_EQ(cv::norm(page, heat, cv::NORM_INF), 0.0);
  EXPECT_FALSE(cv::imread((dir_ / "exports/walk/heatmap_all.png").string()).empty());

  // Bad requests: 4xx, one line, nothing written.
  auto with = [&](const char* key, const json& value) {
    json b = request;
    b[key] = value;
    return b;
  };
  ExpectError(Post("/api/players/export", with("out", "../escaped")), 403, "outside");
  EXPECT_FALSE(fs::exists(dir_.parent_path() / "escaped"));
  ExpectError(Post("/api/players/export", with("out", "WALK.csv")), 400, "not a folder");
  ExpectError(Post("/api/players/export", with("out", ".")), 400, "studio folder");
  ExpectError(Post("/api/players/export", with("tracks", "NONE.csv")), 404, "NONE.csv");
  ExpectError(Post("/api/players/export", with("field", "nowhere")), 404, "unknown field");
  for (const auto& [images, words] : std::vector<std::pair<json, std::string>>{
           {{{"heatmap", "not*base64"}}, "base64"},
           {{{"heatmap", Base64("GIF89a not a png")}}, "not a PNG"},
           // A PNG header saying 16000 x 16000 pixels (1 GB decoded) in a few bytes.
           {{{"heatmap",
              Base64(std::string("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\x3e\x80\0\0\x3e\x80", 24))}},
            "16000x16000 pixels"},
           {{{"../x", heat_url}}, "image name"},
           {{{"heatmap", 3}}, "not a string"},
           {json::array(), "'images'"}}) {
    request["out"] = "exports/bad";
    ExpectError(Post("/api/players/export", with("images", images)), 400, words);
    EXPECT_FALSE(fs::exists(dir_ / "exports/bad")) << words;
  }
  ExpectError(Post("/api/players/export", std::string("{\"out\": ")), 400, "malformed JSON");
  // An export into the folder of its own tracks, named as one of its files, is refused.
  fs::copy_file(dir_ / "WALK.csv", dir_ / "exports/walk/players.csv",
                fs::copy_options::overwrite_existing);
  json own = request;
  own["out"] = "exports/walk";
  own["tracks"] = "exports/walk/players.csv";
  ExpectError(Post("/api/players/export", own), 409, "is read by this export");
  EXPECT_TRUE(fs::exists(dir_ / "exports/walk/notes.txt"));
}

TEST_F(StudioApiTest, ZonesSaveAndRead) {
  FV_SEED_TRACE(seed_);
  const json zones = {{{"name", "box"}, {"polygon", {{-9, -2}, {-7, -2}, {-7, 2}, {-9, 2}}}}};
  const Reply saved = Post("/api/zones/save", json{{"zones", zones}, {"out", "zones.json"}});
  ASSERT_EQ(saved.status, 200) << saved.body;
  const Reply read = Get("/api/zones?path=zones.json");
  ASSERT_EQ(read.status, 200) << read.body;
  EXPECT_EQ(read.j(), zones);
  // A file that is there is replaced only when the request says so (the page asks first).
  ExpectError(Post("/api/zones/save", json{{"zones", zones}, {"out", "zones.json"}}), 409,
              "'zones.json' exists");
  const json bad = {{{"name", "line"}, {"polygon", {{0, 0}, {1, 1}}}}};
  ExpectError(
      Post("/api/zones/save", json{{"zones", bad}, {"out", "zones.json"}, {"replace", true}}), 400,
      "the zones sent: zone 'line' needs 3 or more vertices");
  EXPECT_EQ(Get("/api/zones?path=zones.json").j(), zones);  // the old file is kept
  EXPECT_FALSE(fs::exists(dir_ / "zones.json.check"));
  ExpectError(Get("/api/zones?path=scene/truth.csv"), 422, "not valid JSON");
  // A save never replaces a file of another kind (a video, the scene's truth), and zones must be
  // told apart.
  const auto truth_before = fs::file_size(dir_ / "scene/truth.csv");
  ExpectError(Post("/api/zones/save", json{{"zones", zones}, {"out", "scene/truth.csv"}}), 400,
              "must end in .json");
  EXPECT_EQ(fs::file_size(dir_ / "scene/truth.csv"), truth_before);
  const json twice = {zones[0], zones[0]};
  ExpectError(
      Post("/api/zones/save", json{{"zones", twice}, {"out", "zones.json"}, {"replace", true}}),
      400, "two zones are named 'box'");
  ExpectError(
      Post("/api/colour/save", json{{"range", {{"min", {0, 50, 50}}, {"max", {30, 255, 255}}}},
                                    {"out", "scene/cam1.avi"}}),
      400, "must end in .json");
}

// Polls a job until it is no longer running (at most `seconds`).
json WaitForJob(httplib::Client& client, int id, double seconds) {
  json j;
  for (int i = 0; i < seconds * 20; ++i) {
    auto r = client.Get("/api/jobs");
    if (!r) break;
    for (const auto& job : json::parse(r->body)) {
      if (job["id"] == id) j = job;
    }
    if (j.is_object() && j["state"] != "running") return j;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return j;
}

TEST_F(StudioApiTest, JobsRunAndCancel) {
  FV_SEED_TRACE(seed_);
#ifndef FV_PROGRAM
  GTEST_SKIP() << "the fieldvision program is not built";
#else
  const Reply started =
      Post("/api/jobs", json{{"command", "synth"},
                             {"args",
                              {"--preset", "static", "--frames", "2", "--width", "160", "--height",
                               "120", "--seed", std::to_string(seed_), "--out", "jobs/a"}}});
  ASSERT_EQ(started.status, 200) << started.body;
  const json done = WaitForJob(*client_, started.j()["id"], 120);
  ASSERT_TRUE(done.is_object());
  EXPECT_EQ(done["state"], "done") << done.dump();
  EXPECT_EQ(done["exit_code"], 0);
  EXPECT_TRUE(fs::exists(dir_ / "jobs/a/cam1.avi"));
  // trajectory's outputs besides --out (a new folder for --images) are files inside the folder.
  const std::vector<std::string> fit = {"--in",     "jobs/a/truth.csv", "--out",      "jobs/t.json",
                                        "--report", "jobs/r.json",      "--smoothed", "jobs/s.csv",
                                        "--images", "jobs/pictures"};
  const Reply trajectory = Post("/api/jobs", json{{"command", "trajectory"}, {"args", fit}});
  ASSERT_EQ(trajectory.status, 200) << trajectory.body;
  WaitForJob(*client_, trajectory.j()["id"], 120);
  // Run again, it would write over its outputs: refused unless asked to replace them.
  ExpectError(Post("/api/jobs", json{{"command", "trajectory"}, {"args", fit}}), 409,
              "'jobs/t.json' (--out) exists");
  const Reply again =
      Post("/api/jobs", json{{"command", "trajectory"}, {"args", fit}, {"replace", true}});
  ASSERT_EQ(again.status, 200) << again.body;
  EXPECT_EQ(WaitForJob(*client_, again.j()["id"], 120)["state"], "done");
  std::vector<std::string> outside = fit;
  outside[5] = "../r.json";
  ExpectError(
      Post("/api/jobs", json{{"command", "trajectory"}, {"args", outside}, {"replace", true}}), 403,
      "outside");

  const Reply long_job = Post(
      "/api/jobs", json{{"command", "synth"},
                        {"args", {"--preset", "kick", "--frames", "100000", "--out", "jobs/b"}}});
  ASSERT_EQ(long_job.status, 200) << long_job.body;
  const int id = long_job.j()["id"];
  const Reply cancel = Post("/api/jobs/cancel", json{{"id", id}});
  ASSERT_EQ(cancel.status, 200) << cancel.body;
  EXPECT_TRUE(cancel.j()["cancelled"].get<bool>());
  const json cancelled = WaitForJob(*client_, id, 60);
  EXPECT_EQ(cancelled["state"], "cancelled") << cancelled.dump();
  EXPECT_EQ(Post("/api/jobs/cancel", json{{"id", id}}).j()["cancelled"], false);

  ExpectError(Post("/api/jobs", json{{"command", "rm"}, {"args", {"-rf", "x"}}}), 400,
              "not one of");
  ExpectError(Post("/api/jobs", json{{"command", "synth"}, {"args", {"--out", "../x"}}}), 403,
              "outside");
  ExpectError(Post("/api/jobs", json{{"command", "trajectory"}, {"args", {"--in", "none.csv"}}}),
              404, "does not exist");
  ExpectError(Post("/api/jobs", json{{"command", "synth"}, {"args", {"--preset", "/etc/passwd"}}}),
              400, "looks like a path");
  ExpectError(Post("/api/jobs", json{{"command", "synth"}, {"args", {"--out=/tmp/x"}}}), 400,
              "not an option name");
  ExpectError(Post("/api/jobs/cancel", json{{"id", 999}}), 404, "no job 999");
  // Not truncated to job 3 or cast to another number.
  ExpectError(Post("/api/jobs/cancel", json{{"id", 3.7}}), 400, "integer");
  ExpectError(Post("/api/jobs/cancel", json{{"id", 1e300}}), 400, "integer");
  ExpectError(Post("/api/jobs/cancel", json{{"id", 1LL << 40}}), 400, "integer");
  ExpectError(Post("/api/jobs/cancel", json{{"id", "3"}}), 400, "integer");
#endif
}

TEST_F(StudioApiTest, EventsStreamTellsOfSavedFiles) {
  FV_SEED_TRACE(seed_);
  std::string received;
  std::atomic<bool> hello{false}, saw_saved{false};
  httplib::Client stream("127.0.0.1", port_);
  stream.set_read_timeout(20);
  std::thread reader([&] {
    stream.Get("/api/events", [&](const char* data, size_t n) {
      received.append(data, n);
      if (received.find("event: hello") != std::string::npos) hello = true;
      if (received.find("event: saved") != std::string::npos) {
        saw_saved = true;
        return false;
      }
      return true;
    });
  });
  // Save once the stream has said hello (events before it are not sent to it).
  for (int i = 0; i < 1000 && !hello; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(hello) << "no hello on the event stream";
  const Reply saved =
      Post("/api/colour/save",
           json{{"range", {{"min", {0, 50, 50}}, {"max", {30, 255, 255}}}}, {"out", "c.json"}});
  ASSERT_EQ(saved.status, 200) << saved.body;
  reader.join();
  EXPECT_TRUE(saw_saved);
  EXPECT_NE(received.find("event: hello"), std::string::npos) << received;
  EXPECT_NE(received.find("\"path\":\"c.json\""), std::string::npos) << received;
}

// A stream resumes after the last event its client had (a hidden tab shown again, EventSource's
// own reconnect): what was published meanwhile is replayed. A foreign Host is refused here too
// (the stream tells of jobs, their output and saved files).
TEST_F(StudioApiTest, EventsStreamResumesAfterTheLastEventAndRefusesForeignHosts) {
  FV_SEED_TRACE(seed_);
  ExpectError(Get("/api/events", {{"Host", "evil.example:8470"}}), 403, "loopback host");
  const Reply saved =
      Post("/api/colour/save",
           json{{"range", {{"min", {0, 50, 50}}, {"max", {30, 255, 255}}}}, {"out", "c.json"}});
  ASSERT_EQ(saved.status, 200) << saved.body;
  for (const bool header : {true, false}) {
    std::string received;
    httplib::Client stream("127.0.0.1", port_);
    stream.set_read_timeout(20);
    const auto read = [&](const char* data, size_t n) {
      received.append(data, n);
      return received.find("event: saved") == std::string::npos;
    };
    if (header) {
      stream.Get("/api/events", httplib::Headers{{"Last-Event-ID", "0"}}, read);
    } else {
      stream.Get("/api/events?since=0", read);
    }
    EXPECT_NE(received.find("\"path\":\"c.json\""), std::string::npos) << received;
    EXPECT_NE(received.find("id: 1\n"), std::string::npos) << received;
  }
}

// Event streams (one per studio tab) may hold half the server's threads: with eight open a ninth
// is refused with a one-line 503 and requests are still answered (sixteen held every thread and
// the pages' requests waited); a stream that ends gives its place back.
TEST_F(StudioApiTest, EventStreamsLeaveThreadsForRequests) {
  FV_SEED_TRACE(seed_);
  constexpr int kStreams = 8;
  std::atomic<bool> stop{false};
  std::atomic<int> opened{0};
  std::vector<std::thread> tabs;
  for (int i = 0; i < kStreams; ++i) {
    tabs.emplace_back([&] {
      httplib::Client stream("127.0.0.1", port_);
      stream.set_read_timeout(30);
      bool counted = false;
      stream.Get("/api/events", [&](const char*, size_t) {
        if (!counted) ++opened, counted = true;
        return !stop.load();
      });
    });
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (opened.load() < kStreams && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(opened.load(), kStreams);
  ExpectError(Get("/api/events"), 503, "event streams are open");
  EXPECT_EQ(Get("/api/info").status, 200);
  // The streams end at their next event; their places come back.
  stop = true;
  const Reply saved =
      Post("/api/colour/save",
           json{{"range", {{"min", {0, 50, 50}}, {"max", {30, 255, 255}}}}, {"out", "c.json"}});
  ASSERT_EQ(saved.status, 200) << saved.body;
  for (std::thread& t : tabs) t.join();
  int status = 0;
  while (status != 200 && std::chrono::steady_clock::now() < deadline + std::chrono::seconds(15)) {
    httplib::Client again("127.0.0.1", port_);
    again.set_read_timeout(5);
    // The status from the response's head; the stream itself is not read.
    again.Get(
        "/api/events",
        [&](const httplib::Response& res) {
          status = res.status;
          return false;
        },
        [](const char*, size_t) { return false; });
    if (status != 200) std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  EXPECT_EQ(status, 200);
}

TEST_F(StudioApiTest, TokenRequiredOffLoopback) {
  FV_SEED_TRACE(seed_);
  EXPECT_TRUE(IsLoopback("127.0.0.1"));
  EXPECT_TRUE(IsLoopback("localhost"));
  EXPECT_TRUE(IsLoopback("127.3.2.1"));
  EXPECT_FALSE(IsLoopback("0.0.0.0"));
  EXPECT_FALSE(IsLoopback("127.attacker.example"));
  EXPECT_FALSE(IsLoopback("127.0.0.1.nip.io"));
  EXPECT_FALSE(server_->token_required());
  StudioOptions o;
  o.host = "0.0.0.0";
  o.token = "abc123";
  StartServer(o);
  ASSERT_TRUE(server_->token_required());
  EXPECT_NE(server_->Url().find("?token=abc123"), std::string::npos);
  ExpectError(Get("/api/info"), 401, "token");
  ExpectError(Get("/api/events"), 401, "token");
  ExpectError(Get("/api/info?token=wrong"), 401, "token");
  EXPECT_EQ(Get("/api/info?token=abc123").status, 200);
  EXPECT_EQ(Get("/api/info", {{"X-Studio-Token", "abc123"}}).status, 200);
  o.token = "bad token";
  EXPECT_THROW(StudioServer{o}, fv::Error);
}

TEST_F(StudioApiTest, PageSaysWhenTheFrontEndIsNotBuilt) {
  FV_SEED_TRACE(seed_);
  const Reply missing = Get("/");
  ASSERT_EQ(missing.status, 200);
  EXPECT_NE(missing.body.find("not built"), std::string::npos);
  const fs::path assets = dir_.parent_path() / "assets";
  fs::create_directories(assets);
  std::ofstream(assets / "index.html") << "<html>studio page</html>";
  StudioOptions o;
  o.assets = assets.string();
  StartServer(o);
  EXPECT_TRUE(server_->assets_built());
  const Reply page = Get("/");
  ASSERT_EQ(page.status, 200);
  EXPECT_NE(page.body.find("studio page"), std::string::npos);
  StudioOptions taken;
  taken.port = port_;
  taken.root = dir_.string();
  StudioServer second(taken);
  EXPECT_THROW(second.Start(), fv::Error);
}

}  // namespace
}  // namespace fv::web
