#include "fieldvision/detect/detect_video.h"

#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// An image sequence of a ball rolling across a drawn field, and its camera file.
struct Clip {
  std::string dir, pattern, camera;
  std::vector<Eigen::Vector2d> centres;
};

Clip MakeClip(uint64_t seed, int frames) {
  util::Rng rng(seed);
  Clip clip;
  clip.dir = fv::testing::TempDir();
  std::filesystem::create_directories(clip.dir + "/frames");
  clip.pattern = clip.dir + "/frames/%05d.png";
  const double r = rng.Uniform(5, 12);
  for (int f = 0; f < frames; ++f) {
    cv::Mat img = test_util::FieldImage(320, 240, rng);
    const Eigen::Vector2d c(60 + 40 * f + rng.Uniform(0, 1), 150 + rng.Uniform(0, 1));
    test_util::PaintDisc(img, c, r);
    clip.centres.push_back(c);
    const std::string path = fmt::format("{}/frames/{:05d}.png", clip.dir, f);
    if (!cv::imwrite(path, img)) ADD_FAILURE() << "cannot write " << path;
  }
  clip.camera = clip.dir + "/cam.yaml";
  camera::WriteCameraYaml(camera::Camera::FromFov(320, 240, 60), clip.camera);
  return clip;
}

// `detect` on the clip with its camera, candidates to det.csv, drawn to `draw`.
DetectVideoOptions ClipOptions(const Clip& clip, const std::string& draw) {
  DetectVideoOptions o;
  o.camera = clip.camera;
  o.video = clip.pattern;
  o.out = clip.dir + "/det.csv";
  o.draw = draw;
  o.progress = false;
  return o;
}

TEST(DetectVideo, WritesEveryCandidateAndDrawsThem) {
  const uint64_t seed = fv::testing::TestSeed(12);
  FV_SEED_TRACE(seed);
  Clip clip;
  ASSERT_NO_FATAL_FAILURE(clip = MakeClip(seed, 5));
  const DetectVideoOptions o = ClipOptions(clip, clip.dir + "/drawn");
  const DetectVideoResult r = DetectVideo(o);
  EXPECT_EQ(r.frames, 5);
  EXPECT_EQ(r.frames_with_ball, 5) << r.Summary();
  const util::CsvTable t = util::CsvTable::Read(o.out);
  t.Require({"frame", "u", "v", "radius_px", "score", "accepted", "sigma_px"});
  int accepted = 0;
  for (size_t i = 0; i < t.rows(); ++i) {
    if (t.GetInt(i, "accepted") != 1) continue;
    ++accepted;
    const int f = static_cast<int>(t.GetInt(i, "frame"));
    ASSERT_GE(f, 0);
    ASSERT_LT(f, 5);
    const Eigen::Vector2d uv(t.GetDouble(i, "u"), t.GetDouble(i, "v"));
    EXPECT_LT((uv - clip.centres[f]).norm(), 0.3) << "frame " << f;
    EXPECT_GT(t.GetDouble(i, "sigma_px"), 0.0);
  }
  EXPECT_EQ(accepted, 5);
  for (int f = 0; f < 5; ++f) {
    EXPECT_TRUE(std::filesystem::exists(fmt::format("{}/{:05d}.jpg", o.draw, f)));
  }
  // Each drawn frame has the legend below it: white text on black.
  const cv::Mat first = cv::imread(o.draw + "/00000.jpg");
  const cv::Mat frame = cv::imread(clip.dir + "/frames/00000.png");
  ASSERT_FALSE(first.empty());
  ASSERT_EQ(first.cols, frame.cols);
  const cv::Mat legend = CandidateLegend(frame.cols);
  ASSERT_EQ(first.rows, frame.rows + legend.rows);
  double lo = 0, hi = 0;
  cv::minMaxLoc(first.rowRange(frame.rows, first.rows).reshape(1), &lo, &hi);
  EXPECT_LT(lo, 30);
  EXPECT_GT(hi, 200);
  // An image name draws a still (one frame) into that image, not a folder of that name; for
  // several frames it is an error naming both.
  DetectVideoOptions still = ClipOptions(clip, clip.dir + "/still.png");
  still.video = clip.dir + "/frames/00002.png";
  EXPECT_EQ(DetectVideo(still).drawn, still.draw);
  const cv::Mat drawn = cv::imread(still.draw);
  EXPECT_EQ(drawn.size(), first.size());
  DetectVideoOptions several = ClipOptions(clip, clip.dir + "/several.png");
  EXPECT_THAT(fv::testing::ErrorOf([&] { DetectVideo(several); }),
              ::testing::HasSubstr("names one image but"));
  EXPECT_FALSE(std::filesystem::exists(several.draw));
}

// An annotated video goes to a temporary file renamed over --draw at the end: a run that fails
// on a damaged frame leaves an earlier video as it was; a run that ends says what it drew.
TEST(DetectVideo, ADrawnVideoReplacesAnEarlierOneOnlyWhenTheRunEnds) {
  const uint64_t seed = fv::testing::TestSeed(13);
  FV_SEED_TRACE(seed);
  Clip clip;
  ASSERT_NO_FATAL_FAILURE(clip = MakeClip(seed, 5));
  const DetectVideoOptions o = ClipOptions(clip, clip.dir + "/drawn.avi");
  std::ofstream(o.draw) << "an earlier run's video";
  const std::string damaged = clip.dir + "/frames/00003.png";
  const std::string kept = clip.dir + "/kept.png";
  std::filesystem::rename(damaged, kept);
  std::ofstream(damaged) << "not a PNG";
  EXPECT_THROW(DetectVideo(o), Error);
  std::ifstream in(o.draw);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "an earlier run's video");
  std::filesystem::rename(kept, damaged);
  const DetectVideoResult r = DetectVideo(o);
  EXPECT_NE(r.drawn.find(o.draw), std::string::npos) << r.drawn;
  EXPECT_NE(r.drawn.find("5 frames"), std::string::npos) << r.drawn;
  cv::VideoCapture video(o.draw);
  ASSERT_TRUE(video.isOpened());
  EXPECT_EQ(video.get(cv::CAP_PROP_FRAME_COUNT), 5);
}

// A legend wider than its band wraps onto more lines rather than being cut.
TEST(DetectVideo, LegendWrapsToTheWidth) {
  const cv::Mat wide = CandidateLegend(1280), narrow = CandidateLegend(224);
  EXPECT_EQ(wide.cols, 1280);
  EXPECT_EQ(narrow.cols, 224);
  EXPECT_GT(narrow.rows, 2 * wide.rows - 10);
  const cv::Mat words = TextBand({"a b c d e f g h i j k l m n o p q r s t u v w x y z"}, 60);
  EXPECT_GT(words.rows, 4 * TextBand({"a"}, 60).rows / 2);
}

TEST(DetectVideo, BadInputGivesOneLineErrorsNamingTheInput) {
  Clip clip;
  ASSERT_NO_FATAL_FAILURE(clip = MakeClip(3, 1));
  DetectVideoOptions o;
  o.video = clip.dir + "/missing.avi";
  o.out = clip.dir + "/det.csv";
  o.progress = false;
  std::string e = ErrorOf([&] { DetectVideo(o); });
  EXPECT_NE(e.find("missing.avi"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos);
  // A corrupt video file.
  const std::string corrupt = clip.dir + "/corrupt.avi";
  std::ofstream(corrupt) << "this is not a video";
  o.video = corrupt;
  e = ErrorOf([&] { DetectVideo(o); });
  EXPECT_NE(e.find("corrupt.avi"), std::string::npos) << e;
  // Frames of another size than the camera file.
  const std::string other = clip.dir + "/other.yaml";
  camera::WriteCameraYaml(camera::Camera::FromFov(640, 480, 60), other);
  o.video = clip.pattern;
  o.camera = other;
  e = ErrorOf([&] { DetectVideo(o); });
  EXPECT_NE(e.find("other.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("640x480"), std::string::npos) << e;
  // An empty colour file.
  const std::string empty = clip.dir + "/empty.json";
  std::ofstream(empty) << "";
  o.camera = clip.camera;
  o.detector.colour = empty;
  e = ErrorOf([&] { DetectVideo(o); });
  EXPECT_NE(e.find("empty.json' is empty"), std::string::npos) << e;
}

// A run that fails half-way (a video cut short) leaves the existing output as it was.
TEST(DetectVideo, AFailedRunKeepsTheOldOutput) {
  const std::string dir = fv::testing::TempDir();
  const std::string video = dir + "/cut.avi";
  {
    cv::VideoWriter w(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30, {160, 120});
    ASSERT_TRUE(w.isOpened());
    for (int i = 0; i < 40; ++i) w.write(cv::Mat(120, 160, CV_8UC3, cv::Scalar(40, 120 + i, 50)));
  }
  std::filesystem::resize_file(video, std::filesystem::file_size(video) / 2);
  const std::string out = dir + "/det.csv";
  std::ofstream(out) << "kept\n";
  DetectVideoOptions o;
  o.video = video;
  o.out = out;
  o.progress = false;
  const std::string e = ErrorOf([&] { DetectVideo(o); });
  EXPECT_NE(e.find("cut.avi"), std::string::npos) << e;
  std::ifstream in(out);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "kept");
  for (const auto& f : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(f.path().filename().string().find(".part"), std::string::npos) << f.path();
  }
}

}  // namespace
}  // namespace fv::detect
