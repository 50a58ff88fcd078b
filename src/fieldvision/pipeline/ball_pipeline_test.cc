#include "fieldvision/pipeline/ball_pipeline.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/pipeline/ball_job.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::pipeline {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

constexpr double kRadius = 0.25;
constexpr double kFps = 30.0;

std::vector<camera::Camera> SmallRig() {
  std::vector<camera::Camera> cams;
  const Eigen::Vector3d eyes[3] = {{-6, -5, 3}, {6, -5, 3}, {0, 6, 3}};
  for (int i = 0; i < 3; ++i) {
    camera::Camera c = camera::Camera::FromFov(320, 240, 70);
    c.name = "cam" + std::to_string(i);
    c.cam_from_world = geometry::Rigid3d::LookAt(eyes[i], {0, 0, 0.5});
    c.has_pose = true;
    cams.push_back(c);
  }
  return cams;
}

// Pipeline options for these scenes: the triangulation knows their ball's radius (a camera whose
// ball's size does not fit the point disagrees).
BallPipelineOptions SceneOptions() {
  BallPipelineOptions o;
  o.triangulation.ball_radius_m = kRadius;
  return o;
}

Eigen::Vector3d BallAt(double t) { return {2 * std::sin(t), 1.5 * std::cos(t), 0.5 + 0.3 * t}; }

// An orange disc on green, centred on the projection of the ball centre, as MJPG video whose
// frame f shows time (f + first) / fps.
void WriteVideo(const camera::Camera& cam, const std::string& path, int frames, int first) {
  cv::VideoWriter w(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), kFps,
                    cv::Size(cam.width, cam.height));
  ASSERT_TRUE(w.isOpened());
  for (int f = 0; f < frames; ++f) {
    cv::Mat img(cam.height, cam.width, CV_8UC3, cv::Scalar(60, 130, 60));
    const Eigen::Vector3d p = BallAt((f + first) / kFps);
    const Eigen::Vector2d uv = *cam.Project(p);
    const double r = kRadius * cam.fx / (cam.cam_from_world * p).z();
    const int s = 16;  // 4 bits of sub-pixel precision
    cv::circle(img, cv::Point(std::lround(uv.x() * s), std::lround(uv.y() * s)),
               static_cast<int>(std::lround(r * s)), cv::Scalar(0, 110, 255), cv::FILLED,
               cv::LINE_AA, 4);
    w.write(img);
  }
}

// A simple detector: orange pixels' centroid.
std::vector<recon::BallObservation> Centroid(const cv::Mat& bgr) {
  cv::Mat mask;
  cv::inRange(bgr, cv::Scalar(0, 60, 180), cv::Scalar(90, 170, 255), mask);
  const cv::Moments m = cv::moments(mask, true);
  if (m.m00 < 5) return {};
  recon::BallObservation o;
  o.centre_px = {m.m10 / m.m00, m.m01 / m.m00};
  o.radius_px = std::sqrt(m.m00 / M_PI);
  o.sigma_px = 0.3;
  return {o};
}

// The same, searching only `roi` when one is given (whole-frame pixels).
std::vector<recon::BallObservation> CentroidInWindow(const cv::Mat& bgr, const cv::Rect& roi) {
  if (roi.empty()) return Centroid(bgr);
  auto obs = Centroid(bgr(roi));
  for (auto& o : obs) o.centre_px += Eigen::Vector2d(roi.x, roi.y);
  return obs;
}

struct Scene {
  std::vector<camera::Camera> cams = SmallRig();
  std::vector<std::string> videos;
};

Scene MakeScene(const std::string& dir, const std::vector<int>& lengths,
                const std::vector<int>& firsts) {
  Scene s;
  for (int c = 0; c < 3; ++c) {
    s.videos.push_back(dir + "/cam" + std::to_string(c) + ".avi");
    WriteVideo(s.cams[c], s.videos[c], lengths[c], firsts[c]);
  }
  return s;
}

// `video`'s frames as numbered images folder/NNNNN.ext from `first`; the printf pattern of them.
std::string WriteSequence(const std::string& video, const std::string& folder,
                          const std::string& ext, int first) {
  std::filesystem::create_directories(folder);
  cv::VideoCapture cap(video);
  cv::Mat frame;
  for (int f = first; cap.read(frame); ++f) {
    FV_REQUIRE(cv::imwrite(fmt::format("{}/{:05d}.{}", folder, f, ext), frame),
               "cannot write frame {} of '{}'", f, video);
  }
  return folder + "/%05d." + ext;
}

std::vector<std::unique_ptr<io::FrameSource>> Open(const Scene& s,
                                                   const std::vector<io::FrameSourceOptions>& vo) {
  std::vector<std::unique_ptr<io::FrameSource>> src;
  src.reserve(3);
  for (int c = 0; c < 3; ++c) src.push_back(io::OpenFrameSource(s.videos[c], vo[c]));
  return src;
}

// The tracked pipeline with CentroidInWindow in every camera: the fused frames in order.
std::vector<BallFrame> RunTracked(const Scene& s,
                                  std::vector<std::unique_ptr<io::FrameSource>>& sources,
                                  BallPipelineSummary* summary) {
  BallPipelineOptions opt = SceneOptions();
  opt.progress = false;
  std::vector<BallFrame> frames;
  *summary = RunBallPipelineTracked(s.cams, sources,
                                    {CentroidInWindow, CentroidInWindow, CentroidInWindow}, opt,
                                    [&](const BallFrame& f) { frames.push_back(f); });
  return frames;
}

TEST(BallPipeline, VideosOfDifferentLengthsByFrameIndex) {
  const std::string dir = testing::TempDir();
  const Scene s = MakeScene(dir, {30, 30, 24}, {0, 0, 0});
  auto sources = Open(s, std::vector<io::FrameSourceOptions>(3));
  BallPipelineOptions opt = SceneOptions();
  opt.progress = false;
  std::vector<BallFrame> frames;
  const auto summary = RunBallPipeline(s.cams, sources, {Centroid, Centroid, Centroid}, opt,
                                       [&](const BallFrame& f) { frames.push_back(f); });
  ASSERT_EQ(frames.size(), 30u);
  EXPECT_EQ(summary.frames_with_position, 30);
  for (const BallFrame& f : frames) {
    ASSERT_TRUE(f.result.ok()) << f.frame;
    EXPECT_EQ(f.result.num_views(), f.frame < 24 ? 3 : 2);
    EXPECT_NEAR(f.time_s, f.frame / kFps, 1e-9);
    EXPECT_LT((f.result.point_world - BallAt(f.time_s)).norm(), 0.03) << f.frame;
    EXPECT_LT(f.result.rms_px, 1.0);
  }
  EXPECT_EQ(summary.used_per_camera[2], 24);
  EXPECT_EQ(summary.sync.cameras[2].last_frame, 23);
  EXPECT_NE(summary.ToString().find("sync: cam2: ended at frame 23"), std::string::npos);
}

// Each camera stage tracks the ball: MJPG frames are decoded only in a window around it (and
// whole every few frames or when the window has no ball); the positions are those of the
// whole-frame run.
TEST(BallPipeline, TrackedWindowsGiveTheWholeFramePositions) {
  const std::string dir = testing::TempDir();
  const Scene s = MakeScene(dir, {40, 40, 40}, {0, 0, 0});
  BallPipelineOptions opt = SceneOptions();
  opt.progress = false;
  std::vector<io::FrameSourceOptions> vo(3);
  for (auto& v : vo) v.encoded = true;
  auto whole_sources = Open(s, vo);  // decoded whole (track.enabled is off here)
  std::vector<BallFrame> whole;
  RunBallPipeline(s.cams, whole_sources, {Centroid, Centroid, Centroid}, opt,
                  [&](const BallFrame& f) { whole.push_back(f); });
  auto sources = Open(s, vo);
  for (const auto& src : sources) {
    EXPECT_TRUE(src->encoded());
  }
  int calls_with_window = 0;
  auto in_window = [&](const cv::Mat& bgr, const cv::Rect& roi) {
    calls_with_window += !roi.empty();
    return CentroidInWindow(bgr, roi);
  };
  std::vector<BallFrame> tracked;
  opt.track.full_scan_every = 8;
  const auto summary =
      RunBallPipelineTracked(s.cams, sources, {in_window, in_window, in_window}, opt,
                             [&](const BallFrame& f) { tracked.push_back(f); });
  ASSERT_EQ(tracked.size(), whole.size());
  long long windows = 0, fulls = 0;
  for (int c = 0; c < 3; ++c) {
    windows += summary.window_scans[c];
    fulls += summary.full_scans[c];
  }
  EXPECT_EQ(windows, calls_with_window);
  EXPECT_GE(windows, 3 * 40 * 6 / 8);  // 7 of every 8 frames after the first
  EXPECT_EQ(windows + fulls, 3 * 40 + 0);
  for (size_t i = 0; i < tracked.size(); ++i) {
    ASSERT_TRUE(tracked[i].result.ok()) << i;
    ASSERT_TRUE(whole[i].result.ok()) << i;
    EXPECT_LT((tracked[i].result.point_world - whole[i].result.point_world).norm(), 1e-9) << i;
    EXPECT_LT((tracked[i].result.point_world - BallAt(tracked[i].time_s)).norm(), 0.03) << i;
  }
}

// A pattern of JPEG files (dir/%05d.jpg, from index 1) is read as encoded frames too: the same
// pixels as OpenCV's reader, and the tracked pipeline finds the ball in every frame.
TEST(BallPipeline, JpegSequencesAreDecodedInWindows) {
  const std::string dir = testing::TempDir();
  const Scene s = MakeScene(dir, {24, 24, 24}, {0, 0, 0});
  std::vector<std::string> patterns;
  for (int c = 0; c < 3; ++c) {
    patterns.push_back(WriteSequence(s.videos[c], dir + "/seq" + std::to_string(c), "jpg", 1));
  }
  io::FrameSourceOptions enc;
  enc.encoded = true;
  enc.fps = kFps;  // image files have no frame rate
  {
    auto src_ptr = io::OpenFrameSource(patterns[0], enc);
    io::FrameSource& src = *src_ptr;
    EXPECT_TRUE(src.encoded());
    EXPECT_EQ(src.FrameCount(), 24);
    auto plain_ptr = io::OpenFrameSource(patterns[0]);
    io::FrameSource& plain = *plain_ptr;
    EXPECT_FALSE(plain.encoded());
    cv::Mat a;
    long long fa;
    double ta;
    for (int f = 0; f < 24; ++f) {
      ASSERT_TRUE(src.Read(&a, &fa, &ta));
      EXPECT_EQ(fa, f);
      EXPECT_DOUBLE_EQ(ta, f / kFps);
      // The pixels of OpenCV's JPEG reader (libjpeg-turbo, the same settings).
      const cv::Mat b = cv::imread(fmt::format("{}/seq0/{:05d}.jpg", dir, f + 1));
      EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << "frame " << f;
    }
    EXPECT_FALSE(src.Read(&a, &fa, &ta));
  }
  std::vector<std::unique_ptr<io::FrameSource>> sources;
  sources.reserve(patterns.size());
  for (const auto& p : patterns) sources.push_back(io::OpenFrameSource(p, enc));
  BallPipelineSummary summary;
  const std::vector<BallFrame> frames = RunTracked(s, sources, &summary);
  ASSERT_EQ(frames.size(), 24u);
  EXPECT_GT(summary.window_scans[0], 12);
  for (const BallFrame& f : frames) {
    ASSERT_TRUE(f.result.ok()) << f.frame;
    EXPECT_LT((f.result.point_world - BallAt(f.time_s)).norm(), 0.03) << f.frame;
  }
}

// A damaged frame in one MJPG video is reported and skipped; the other cameras carry on.
TEST(BallPipeline, DamagedMjpgFrameIsReportedNotFatal) {
  const std::string dir = testing::TempDir();
  const Scene s = MakeScene(dir, {20, 20, 20}, {0, 0, 0});
  {
    // Overwrite the header of cam1's frame 5 (the 6th JPEG start in the file) with zeros.
    std::fstream f(s.videos[1], std::ios::in | std::ios::out | std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    size_t pos = 0;
    for (int k = 0; k <= 5; ++k) {
      pos = bytes.find("\xFF\xD8\xFF", k == 0 ? 0 : pos + 3);
      ASSERT_NE(pos, std::string::npos);
    }
    f.seekp(static_cast<std::streamoff>(pos + 2));
    const std::string zeros(64, '\0');
    f.write(zeros.data(), static_cast<std::streamsize>(zeros.size()));
  }
  std::vector<io::FrameSourceOptions> vo(3);
  for (auto& v : vo) v.encoded = true;
  auto sources = Open(s, vo);
  BallPipelineSummary summary;
  const std::vector<BallFrame> frames = RunTracked(s, sources, &summary);
  ASSERT_EQ(frames.size(), 20u);
  EXPECT_EQ(summary.bad_frames[1], 1);
  EXPECT_NE(summary.first_bad_frame[1].find("cam1.avi' frame 5"), std::string::npos)
      << summary.first_bad_frame[1];
  EXPECT_NE(summary.ToString().find("1 frames could not be decoded"), std::string::npos);
  for (const BallFrame& f : frames) {
    ASSERT_TRUE(f.result.ok()) << f.frame;
    EXPECT_EQ(f.result.num_views(), f.frame == 5 ? 2 : 3) << f.frame;
  }
}

TEST(BallPipeline, UnsynchronizedVideosPairedByTimestampCsv) {
  const std::string dir = testing::TempDir();
  // Camera 2 started 3 frames late: by index the frames would be paired wrongly.
  const Scene s = MakeScene(dir, {30, 30, 27}, {0, 0, 3});
  std::vector<io::FrameSourceOptions> vo(3);
  for (int c = 0; c < 3; ++c) {
    const std::string csv_path = dir + "/cam" + std::to_string(c) + "_times.csv";
    util::CsvWriter csv(csv_path, {"frame", "time_s"}, 9);
    for (int f = 0; f < 30; ++f) {
      csv << f << (f + (c == 2 ? 3 : 0)) / kFps;
      csv.EndRow();
    }
    csv.Close();
    vo[c].time = io::TimeSource::kCsv;
    vo[c].timestamps_csv = csv_path;
  }
  BallPipelineOptions opt = SceneOptions();
  opt.progress = false;
  opt.sync.mode = SyncMode::kTimestamp;
  opt.sync.tolerance_s = 0.3 / kFps;
  auto sources = Open(s, vo);
  std::vector<BallFrame> frames;
  RunBallPipeline(s.cams, sources, {Centroid, Centroid, Centroid}, opt,
                  [&](const BallFrame& f) { frames.push_back(f); });
  ASSERT_EQ(frames.size(), 30u);
  double sum_time = 0, sum_index = 0;
  for (const BallFrame& f : frames) {
    ASSERT_TRUE(f.result.ok()) << f.frame;
    EXPECT_EQ(f.result.num_views(), f.frame < 3 ? 2 : 3);
    const double err = (f.result.point_world - BallAt(f.time_s)).norm();
    EXPECT_LT(err, 0.03) << f.frame;
    sum_time += err;
  }
  // The same videos paired by index put camera 2 three frames off: much worse.
  opt.sync.mode = SyncMode::kFrameIndex;
  auto again = Open(s, std::vector<io::FrameSourceOptions>(3));
  int n_index = 0;
  RunBallPipeline(s.cams, again, {Centroid, Centroid, Centroid}, opt, [&](const BallFrame& f) {
    if (!f.result.ok()) return;
    sum_index += (f.result.point_world - BallAt(f.time_s)).norm();
    ++n_index;
  });
  ASSERT_GT(n_index, 0);
  EXPECT_GT(sum_index / n_index, 3 * sum_time / frames.size());
}

TEST(BallPipeline, CameraFileForAnotherResolutionIsAClearError) {
  const std::string dir = testing::TempDir();
  const Scene s = MakeScene(dir, {3, 3, 3}, {0, 0, 0});
  auto cams = s.cams;
  cams[1] = camera::Camera::FromFov(640, 480, 70);
  cams[1].cam_from_world = s.cams[1].cam_from_world;
  cams[1].has_pose = true;
  auto sources = Open(s, std::vector<io::FrameSourceOptions>(3));
  BallPipelineOptions opt = SceneOptions();
  opt.progress = false;
  EXPECT_THAT(
      [&] {
        RunBallPipeline(cams, sources, {Centroid, Centroid, Centroid}, opt,
                        [](const BallFrame&) {});
      },
      ThrowsMessage<Error>(::testing::AllOf(HasSubstr("640x480"), HasSubstr("320x240"),
                                            HasSubstr("cam1.avi"),
                                            ::testing::Not(HasSubstr("\n")))));
  // The same through the job, with camera files.
  BallJobOptions job;
  for (int c = 0; c < 3; ++c) {
    job.cameras.push_back(dir + "/cam" + std::to_string(c) + ".yaml");
    camera::WriteCameraYaml(cams[c], job.cameras.back());
  }
  job.videos = s.videos;
  job.out = dir + "/ball.csv";
  job.pipeline.progress = false;
  EXPECT_THAT([&] { RunBallJob(job); },
              ThrowsMessage<Error>(::testing::AllOf(HasSubstr("cam1.yaml"), HasSubstr("640x480"),
                                                    HasSubstr("320x240"))));
  EXPECT_FALSE(std::filesystem::exists(job.out));
}

// A 6-frame scene in `dir` (created).
Scene SixFrameJobScene(const std::string& dir) {
  std::filesystem::create_directories(dir);
  return MakeScene(dir, {6, 6, 6}, {0, 0, 0});
}

// A ball job on `s`'s videos, its camera files written to `dir`, BALL.csv there.
BallJobOptions JobOn(const Scene& s, const std::string& dir) {
  BallJobOptions job;
  for (int c = 0; c < 3; ++c) {
    job.cameras.push_back(dir + "/cam" + std::to_string(c) + ".yaml");
    camera::WriteCameraYaml(s.cams[c], job.cameras.back());
  }
  job.videos = s.videos;
  job.out = dir + "/ball.csv";
  job.pipeline.progress = false;
  return job;
}

// Cameras at one place (a camera file copied under another name) triangulate nothing: an error
// naming the files instead of a BALL.csv without rows; one pair apart is enough.
TEST(BallPipeline, ARigOfCamerasAtOnePlaceIsRefused) {
  const Scene s;
  camera::Camera copy = s.cams[0];
  copy.name = "copy";
  EXPECT_THAT(
      [&] {
        CheckRigSpread({s.cams[0], copy}, {"a.yaml", "b.yaml"});
      },
      ThrowsMessage<Error>(
          ::testing::AllOf(HasSubstr("'a.yaml'"), HasSubstr("'b.yaml'"), HasSubstr("one place"))));
  EXPECT_NO_THROW(CheckRigSpread({s.cams[0], copy, s.cams[1]}, {"a.yaml", "b.yaml", "c.yaml"}));
  EXPECT_NO_THROW(CheckRigSpread({s.cams[0]}, {"a.yaml"}));
}

// A run without one position (here the wrong colour) writes the header (a video without the
// ball has none) and says why.
TEST(BallPipeline, AJobWithoutAPositionSaysWhy) {
  const std::string dir = testing::TempDir() + "/job_no_position";
  const Scene s = SixFrameJobScene(dir);
  BallJobOptions job = JobOn(s, dir);
  job.ball_diameter_m = 2 * kRadius;
  const BallJobResult found = RunBallJob(job);
  ASSERT_GT(found.rows_written, 0);
  EXPECT_EQ(found.NoPositionWarning(), "");
  job.colour = "blue";
  const BallJobResult none = RunBallJob(job);
  EXPECT_EQ(none.rows_written, 0);
  EXPECT_EQ(util::CsvTable::Read(job.out).rows(), 0u);
  EXPECT_THAT(none.NoPositionWarning(),
              ::testing::AllOf(HasSubstr("no ball position in 6 frames"), HasSubstr("cam0 0"),
                               HasSubstr("--color"), ::testing::Not(HasSubstr("\n"))));
}

// Pairing frames by index needs one frame rate: a camera at another rate is refused naming both
// videos (the fused times would go back where the shorter video ends), unless timestamps pair
// them.
TEST(BallPipeline, TheJobRefusesFrameIndexPairingAcrossFrameRates) {
  const std::string dir = testing::TempDir() + "/job_rates";
  const Scene s = SixFrameJobScene(dir);
  BallJobOptions job = JobOn(s, dir);
  // The third camera's frames again, at twice the rate.
  job.videos[2] = dir + "/cam2_60.avi";
  {
    cv::VideoCapture in(s.videos[2]);
    cv::VideoWriter out(job.videos[2], cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 2 * kFps,
                        cv::Size(s.cams[2].width, s.cams[2].height));
    cv::Mat f;
    while (in.read(f)) out.write(f);
  }
  EXPECT_THAT([&] { RunBallJob(job); },
              ThrowsMessage<Error>(::testing::AllOf(HasSubstr("--sync frame"),
                                                    HasSubstr("cam0.avi"), HasSubstr("cam2_60.avi"),
                                                    ::testing::Not(HasSubstr("\n")))));
  EXPECT_FALSE(std::filesystem::exists(job.out));
}

// Times are taken from the videos, never assumed: image sequences have no frame rate, so the job
// refuses them (naming the sequence) without --fps or --timestamps, and takes times from --fps.
TEST(BallPipeline, TheJobNeedsAFrameRateForImageSequences) {
  const std::string dir = testing::TempDir() + "/job_sequence_rate";
  const Scene s = SixFrameJobScene(dir);
  BallJobOptions job = JobOn(s, dir);
  for (int c = 0; c < 3; ++c) {
    job.videos[c] = WriteSequence(s.videos[c], dir + "/seq" + std::to_string(c), "png", 0);
  }
  job.ball_diameter_m = 2 * kRadius;
  EXPECT_THAT([&] { RunBallJob(job); }, ThrowsMessage<Error>(::testing::AllOf(
                                            HasSubstr("seq0/%05d.png"), HasSubstr("no frame rate"),
                                            HasSubstr("--fps"), ::testing::Not(HasSubstr("\n")))));
  EXPECT_FALSE(std::filesystem::exists(job.out));
  job.fps = 2 * kFps;
  RunBallJob(job);
  // A video's own rate must agree with --fps (it is for image sequences).
  BallJobOptions videos = JobOn(s, dir);
  videos.fps = 2 * kFps;
  EXPECT_THAT([&] { RunBallJob(videos); },
              ThrowsMessage<Error>(::testing::AllOf(HasSubstr("--fps"), HasSubstr("cam0.avi"))));
  const util::CsvTable t = util::CsvTable::Read(job.out);
  ASSERT_GT(t.rows(), 0u);
  for (size_t i = 0; i < t.rows(); ++i) {
    EXPECT_NEAR(t.GetDouble(i, "time_s"), t.GetDouble(i, "frame") / (2 * kFps), 1e-5) << i;
  }
}

// The job on videos: each camera's accepted candidates written as DET.csv (one row a frame
// here), and the flight bundle at the end never moving a ball that does not fly freely (this one
// is carried along a helix) away from where the frames put it.
TEST(BallPipeline, TheJobWritesEachCamerasDetectionsAndKeepsANonBallisticTrack) {
  const std::string dir = testing::TempDir() + "/job_detections";
  std::filesystem::create_directories(dir);
  constexpr int kFrames = 24;
  const Scene s = MakeScene(dir, {kFrames, kFrames, kFrames}, {0, 0, 0});
  BallJobOptions job;
  for (int c = 0; c < 3; ++c) {
    job.cameras.push_back(dir + "/cam" + std::to_string(c) + ".yaml");
    camera::WriteCameraYaml(s.cams[c], job.cameras.back());
    job.detections_out.push_back(dir + "/det" + std::to_string(c) + ".csv");
  }
  job.videos = s.videos;
  job.ball_diameter_m = 2 * kRadius;
  job.pipeline.progress = false;
  double max_err_m[2] = {0, 0};
  for (const bool bundle : {false, true}) {
    job.bundle = bundle;
    job.out = dir + (bundle ? "/ball_bundled.csv" : "/ball.csv");
    const BallJobResult r = RunBallJob(job);
    EXPECT_EQ(r.rows_written, kFrames) << "bundle " << bundle;
    EXPECT_EQ(r.bundle.has_value(), bundle);
    const util::CsvTable t = util::CsvTable::Read(job.out);
    for (size_t i = 0; i < t.rows(); ++i) {
      const Eigen::Vector3d p(t.GetDouble(i, "x_m"), t.GetDouble(i, "y_m"), t.GetDouble(i, "z_m"));
      max_err_m[bundle] =
          std::max(max_err_m[bundle], (p - BallAt(t.GetDouble(i, "time_s"))).norm());
    }
  }
  EXPECT_LT(max_err_m[0], 0.02);
  EXPECT_LT(max_err_m[1], 0.02);
  for (int c = 0; c < 3; ++c) {
    const util::CsvTable d = util::CsvTable::Read(job.detections_out[c]);
    ASSERT_EQ(d.rows(), static_cast<size_t>(kFrames)) << "camera " << c;
    for (size_t i = 0; i < d.rows(); ++i) {
      const Eigen::Vector2d uv = *s.cams[c].Project(BallAt(d.GetDouble(i, "time_s")));
      EXPECT_LT((Eigen::Vector2d(d.GetDouble(i, "u"), d.GetDouble(i, "v")) - uv).norm(), 0.5)
          << "camera " << c << " row " << i;
    }
  }
  // One file per camera or none.
  job.detections_out.pop_back();
  EXPECT_THROW(job.Check(), Error);
}

// The pipeline's stages one by one, in one thread: each camera's stream read into its queue
// (stopping at max_frames), then fused; the counts as the whole pipeline gives them.
TEST(BallPipelineStages, ReadThenFuseInOneThread) {
  EXPECT_EQ(ExpectedPipelineFrames({30, 30, 24}, 0), 30);
  EXPECT_EQ(ExpectedPipelineFrames({30, -1}, 0), 30);
  EXPECT_EQ(ExpectedPipelineFrames({-1, -1}, 0), -1);
  EXPECT_EQ(ExpectedPipelineFrames({30, 24}, 10), 10);
  EXPECT_EQ(ExpectedPipelineFrames({5}, 10), 5);
  EXPECT_EQ(ExpectedPipelineFrames({-1}, 10), -1);

  const std::string dir = testing::TempDir();
  Scene s = MakeScene(dir, {20, 20, 12}, {0, 0, 0});
  s.cams[1].name.clear();
  auto sources = Open(s, std::vector<io::FrameSourceOptions>(3));
  const std::vector<BallRegionDetectFn> detectors(3, CentroidInWindow);
  CheckBallPipelineInputs(s.cams, sources, detectors);
  EXPECT_THROW(CheckBallPipelineInputs(s.cams, sources, {CentroidInWindow}), Error);
  BallPipelineSummary summary = EmptyBallPipelineSummary(s.cams);
  EXPECT_EQ(summary.camera_names, (std::vector<std::string>{"cam0", "camera 1", "cam2"}));
  ASSERT_EQ(summary.window_scans.size(), 3u);

  BallPipelineOptions opt = SceneOptions();
  opt.progress = false;
  CameraQueues queues;
  const std::function<bool()> never = [] { return false; };
  for (int c = 0; c < 3; ++c) {
    queues.push_back(std::make_unique<BoundedQueue<CameraMessage>>(100, QueuePolicy::kBlock));
    CameraStage stage(c, s.cams[c], detectors[c], opt.track, sources[c]->name());
    ReadCameraStream(*sources[c], stage, *queues[c], 15, never);
    EXPECT_EQ(stage.stats().frames, c < 2 ? 15 : 12);
  }
  std::vector<BallFrame> frames;
  FuseCameraQueues(
      s.cams, queues, opt, 15, never, [&](const BallFrame& f) { frames.push_back(f); }, &summary);
  ASSERT_EQ(frames.size(), 15u);
  EXPECT_EQ(summary.frames, 15);
  EXPECT_EQ(summary.frames_with_position, 15);
  EXPECT_EQ(summary.used_per_camera, (std::vector<long long>{15, 15, 12}));
  EXPECT_EQ(summary.sync.cameras[2].last_frame, 11);
  double sum_err = 0;
  for (const BallFrame& f : frames) {
    ASSERT_TRUE(f.result.ok()) << f.frame;
    EXPECT_LT((f.result.point_world - BallAt(f.time_s)).norm(), 0.03) << f.frame;
    sum_err += f.result.rms_px;
  }
  EXPECT_NEAR(summary.mean_err_px, sum_err / 15, 1e-9);
}

TEST(BallPipeline, BadInputsAreOneLineErrors) {
  const std::string dir = testing::TempDir();
  EXPECT_THROW(io::OpenFrameSource(dir + "/missing.avi"), Error);
  {
    std::ofstream junk(dir + "/junk.avi");
    junk << "this is not a video";
  }
  EXPECT_THROW(io::OpenFrameSource(dir + "/junk.avi"), Error);
  BallJobOptions job;
  job.cameras = {"a.yaml", "b.yaml"};
  job.videos = {"a.avi"};
  job.out = dir + "/x.csv";
  EXPECT_THROW(job.Check(), Error);
  job.videos = {"a.avi", "b.avi"};
  job.ball_diameter_m = NAN;
  EXPECT_THROW(job.Check(), Error);
  job.ball_diameter_m = 0.22;
  job.dnn.detector = "yolo";
  EXPECT_NE(testing::ErrorOf([&] { job.Check(); }).find("--detector"), std::string::npos);
}

}  // namespace
}  // namespace fv::pipeline
