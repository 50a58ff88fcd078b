// The frame-source backends: files (plain, encoded, played in real time), synth scenes played
// live, GStreamer, V4L2 (the kernel's vivid test driver) and Aravis' simulated camera where
// this machine has them; unknown schemes.
#include "fieldvision/io/frame_source.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/io/io_testing.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::io {
namespace {

std::string WriteMjpg(const std::string& dir, int frames, double fps,
                      const std::string& name = "v.avi") {
  std::string path = dir + "/" + name;
  cv::VideoWriter w(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, cv::Size(64, 48));
  for (int i = 0; i < frames; ++i) w.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(10 * i, 80, 200)));
  return path;
}

TEST(FrameSource, FileEncodedAndDecodedAgree) {
  const std::string video = WriteMjpg(testing::TempDir(), 5, 25);
  FrameSourceOptions enc;
  enc.encoded = true;
  auto a = OpenFrameSource(video, enc);
  auto b = OpenFrameSource(video);
  EXPECT_TRUE(a->encoded());
  EXPECT_FALSE(b->encoded());
  EXPECT_FALSE(a->live());
  EXPECT_EQ(a->FrameSize(), cv::Size(64, 48));
  cv::Mat ma;
  SourceFrame fb;
  long long fa = 0;
  double ta = 0;
  int n = 0;
  while (a->Read(&ma, &fa, &ta)) {
    ASSERT_TRUE(b->ReadFrame(&fb));
    EXPECT_EQ(fa, n);
    EXPECT_EQ(fb.frame, n);
    EXPECT_DOUBLE_EQ(ta, n / 25.0);
    EXPECT_EQ(fb.origin, TimeOrigin::kFrameRate);
    // Both decoded by libjpeg-turbo: the same pixels.
    EXPECT_EQ(cv::norm(ma, fb.bgr, cv::NORM_INF), 0);
    ++n;
  }
  EXPECT_EQ(n, 5);
}

// Container times asked for (`ball --sync time`): raw MJPG packets carry none that OpenCV
// reports (every frame was at 0 s), so an AVI's come from its fixed rate and another container
// is decoded by FFmpeg, which reports its times.
TEST(FrameSource, EncodedFramesKeepContainerTimes) {
  FrameSourceOptions o;
  o.encoded = true;
  o.time = TimeSource::kContainer;
  auto avi = OpenFrameSource(WriteMjpg(testing::TempDir(), 5, 25), o);
  EXPECT_TRUE(avi->encoded());
  auto mkv = OpenFrameSource(WriteMjpg(testing::TempDir(), 5, 25, "v.mkv"), o);
  EXPECT_FALSE(mkv->encoded());
  for (auto* src : {avi.get(), mkv.get()}) {
    SourceFrame f;
    int n = 0;
    while (src->ReadFrame(&f)) {
      EXPECT_EQ(f.frame, n);
      EXPECT_NEAR(f.time_s, n / 25.0, 1e-3) << src->name();
      EXPECT_EQ(f.origin, TimeOrigin::kContainer);
      ++n;
    }
    EXPECT_EQ(n, 5) << src->name();
  }
}

// A glob and a folder of JPEG files: name order, encoded on request (the files' bytes) and
// decoded alike, times from the given rate; a size check names the camera file.
TEST(FrameSource, ImageGlobAndFolderEncodedOrNot) {
  const std::string dir = testing::TempDir() + "/glob";
  std::filesystem::create_directories(dir);
  for (int i = 0; i < 4; ++i) {
    cv::imwrite(fmt::format("{}/f{:02d}.jpg", dir, i),
                cv::Mat(48, 64, CV_8UC3, cv::Scalar(40 * i, 100, 200 - 40 * i)));
  }
  for (const std::string& spec : {dir + "/f*.jpg", dir}) {
    for (const bool encoded : {false, true}) {
      SCOPED_TRACE(spec + (encoded ? " encoded" : ""));
      FrameSourceOptions o;
      o.fps = 20;
      o.encoded = encoded;
      auto src = OpenFrameSource(spec, o);
      EXPECT_EQ(src->FrameCount(), 4);
      EXPECT_EQ(src->encoded(), encoded);
      EXPECT_EQ(src->FrameSize(), cv::Size(64, 48));
      cv::Mat bgr;
      long long frame = -1;
      double t = -1;
      int n = 0;
      while (src->Read(&bgr, &frame, &t)) {
        EXPECT_EQ(frame, n);
        EXPECT_DOUBLE_EQ(t, n / 20.0);
        EXPECT_NEAR(bgr.at<cv::Vec3b>(10, 10)[0], 40 * n, 4);
        ++n;
      }
      EXPECT_EQ(n, 4);
      camera::Camera cam = camera::Camera::FromFov(640, 480, 60);
      try {
        FitCameraToSource(*src, cam, "cam.yaml");
        ADD_FAILURE() << "no size error";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("cam.yaml"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("64x48"), std::string::npos) << e.what();
      }
    }
  }
  EXPECT_THROW(OpenFrameSource(dir + "/none*.png"), Error);
}

// An image sequence has no frame rate of its own: none is known (fps() a stand-in) unless given,
// or declared by a synth scene.json beside the images or one folder up; a video knows its own.
TEST(FrameSource, AnImageSequenceKnowsARateOnlyWhenGivenOne) {
  const std::string dir = testing::TempDir() + "/rate";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir + "/cam1");
  for (int i = 0; i < 3; ++i) {
    cv::imwrite(fmt::format("{}/cam1/{:05d}.png", dir, i), cv::Mat(48, 64, CV_8UC3, cv::Scalar(i)));
  }
  const std::string spec = dir + "/cam1/%05d.png";
  EXPECT_FALSE(OpenFrameSource(spec)->rate_known());
  FrameSourceOptions given;
  given.fps = 25;
  EXPECT_TRUE(OpenFrameSource(spec, given)->rate_known());
  EXPECT_DOUBLE_EQ(OpenFrameSource(spec, given)->fps(), 25.0);
  std::ofstream(dir + "/scene.json") << R"({"fps": 60.0, "num_frames": 3})";
  auto src = OpenFrameSource(spec);
  EXPECT_TRUE(src->rate_known());
  EXPECT_DOUBLE_EQ(src->fps(), 60.0);
  cv::Mat bgr;
  long long frame = 0;
  double t = 0;
  ASSERT_TRUE(src->Read(&bgr, &frame, &t) && src->Read(&bgr, &frame, &t));
  EXPECT_DOUBLE_EQ(t, 1 / 60.0);
  std::ofstream(dir + "/scene.json") << R"({"fps": "fast"})";
  EXPECT_FALSE(OpenFrameSource(spec)->rate_known());
  const std::string video = dir + "/v.avi";
  {
    cv::VideoWriter w(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 50, cv::Size(64, 48));
    for (int i = 0; i < 3; ++i) w.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(i)));
  }
  EXPECT_TRUE(OpenFrameSource(video)->rate_known());
  EXPECT_DOUBLE_EQ(OpenFrameSource(video)->fps(), 50.0);
}

TEST(FrameSource, TruncatedFileFailsAtItsEndEncodedOrNot) {
  const std::string video = test_util::WriteTruncatedMjpg(testing::TempDir() + "/cut.avi", 0.5);
  for (const bool encoded : {false, true}) {
    SCOPED_TRACE(encoded ? "encoded" : "decoded");
    FrameSourceOptions o;
    o.encoded = encoded;
    auto src = OpenFrameSource(video, o);
    SourceFrame f;
    int n = 0;
    try {
      while (src->ReadFrame(&f)) ++n;
      ADD_FAILURE() << "ended after " << n << " frames without an error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("of the 16 frames"), std::string::npos) << e.what();
    }
    EXPECT_LT(n, 16);
  }
}

// Issue 18: a --timestamps file is read whole and checked before any frame: a negative frame, a
// time that is not a number in range or that does not increase with the frame is an error naming
// file and line, for a video file and for a folder of images alike.
TEST(FrameSource, TimestampsCsvRangesNameFileAndLine) {
  const std::string dir = testing::TempDir();
  const std::string video = WriteMjpg(dir, 3, 25);
  const std::string good = dir + "/ts.csv";
  std::ofstream(good) << "frame,time_s\n1,0.04\n0,0\n2,0.08\n";
  const std::map<long long, double> times = ReadTimestampsCsv(good);
  ASSERT_EQ(times.size(), 3u);
  EXPECT_DOUBLE_EQ(times.at(1), 0.04);
  const struct {
    const char* rows;  // rows 3 and 4 (lines 4 and 5) after 0,0 and 1,0.04
    const char* line;  // the line the error names
    const char* says;
  } cases[] = {
      {"2,-0.08\n3,0.12\n", "bad.csv:4", "not in [0"},
      {"2,nan\n3,0.12\n", "bad.csv:4", "not in [0"},
      {"2,1e300\n3,0.12\n", "bad.csv:4", "not in [0"},
      {"2,soon\n3,0.12\n", "bad.csv:4", "soon"},
      {"-2,0.08\n3,0.12\n", "bad.csv:4", "negative"},
      {"2,0.08\n3,0.02\n", "bad.csv:5", "not after"},
      {"2,0.08\n3,0.08\n", "bad.csv:5", "not after"},
      {"2,0.08\n1,0.12\n", "bad.csv:5", "listed twice"},
  };
  const std::string bad = dir + "/bad.csv";
  cv::imwrite(dir + "/a.png", cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(90)));
  for (const auto& c : cases) {
    SCOPED_TRACE(c.rows);
    std::ofstream(bad, std::ios::trunc) << "frame,time_s\n0,0\n1,0.04\n" << c.rows;
    FrameSourceOptions o;
    o.time = TimeSource::kCsv;
    o.timestamps_csv = bad;
    for (const std::string& spec : {video, dir + "/*.png"}) {
      try {
        OpenFrameSource(spec, o);
        ADD_FAILURE() << "accepted for " << spec;
      } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(c.line), std::string::npos) << msg;
        EXPECT_NE(msg.find(c.says), std::string::npos) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      }
    }
  }
  std::ofstream(bad, std::ios::trunc) << "frame,time_s\n";
  EXPECT_THROW(ReadTimestampsCsv(bad), Error);
  // Milliseconds (40 "s" a frame at 25 frames/s) are said, not taken as a 0.025 frames/s video.
  std::ofstream(bad, std::ios::trunc) << "frame,time_s\n0,0\n1,40\n2,80\n3,120\n";
  EXPECT_NE(testing::ErrorOf([&] { ReadTimestampsCsv(bad); }).find("frames are 40 s apart"),
            std::string::npos);
}

TEST(FrameSource, RealtimeFileIsStampedOnTheSystemClockAndSkipsWhatIsGone) {
  const std::string video = WriteMjpg(testing::TempDir(), 4, 50);
  FrameSourceOptions o;
  o.realtime = true;
  o.start_at_s = SystemClockNow();
  auto src = OpenFrameSource(video, o);
  EXPECT_TRUE(src->live());
  SourceFrame f;
  for (int k = 0; k < 4; ++k) {
    ASSERT_TRUE(src->ReadFrame(&f));
    EXPECT_EQ(f.origin, TimeOrigin::kPlayback);
    EXPECT_DOUBLE_EQ(f.time_s, o.start_at_s + k / 50.0);
  }
  EXPECT_FALSE(src->ReadFrame(&f));
  // Started long ago with one frame of buffer: every frame is gone, and counted.
  o.start_at_s = SystemClockNow() - 100;
  o.live_buffer_frames = 1;
  auto late = OpenFrameSource(video, o);
  EXPECT_FALSE(late->ReadFrame(&f));
  EXPECT_EQ(late->dropped(), 4);
}

TEST(FrameSource, SynthSceneIsPlayedLive) {
  FrameSourceOptions o;
  o.encoded = true;
  // On the world's clock: the scene loops, frames at multiples of 1 / fps in Unix time.
  auto src = OpenFrameSource("synth:kick?camera=1&width=160&height=120&frames=3", o);
  EXPECT_TRUE(src->live());
  EXPECT_TRUE(src->encoded());
  EXPECT_EQ(src->FrameSize(), cv::Size(160, 120));
  EXPECT_EQ(src->FrameCount(), -1);
  cv::Mat bgr;
  long long frame = 0;
  double t = 0, last = 0;
  for (int k = 0; k < 5; ++k) {  // more than the scene's 3 frames
    ASSERT_TRUE(src->Read(&bgr, &frame, &t));
    EXPECT_EQ(bgr.size(), cv::Size(160, 120));
    const double ticks = t * 60;
    EXPECT_NEAR(ticks, std::round(ticks), 1e-3);  // on the 60 fps grid (0.24 us resolution)
    if (k > 0) EXPECT_GE(t - last, 1.0 / 60 - 1e-6);
    last = t;
  }
  // From a given start: frames 0..2 at start + k / fps, then the end.
  o.start_at_s = SystemClockNow();
  auto once = OpenFrameSource("synth:kick?camera=cam2&width=160&height=120&frames=3", o);
  EXPECT_EQ(once->FrameCount(), 3);
  int n = 0;
  SourceFrame f;
  while (once->ReadFrame(&f)) {
    EXPECT_NEAR(f.time_s, o.start_at_s + f.frame / 60.0, 1e-6);
    ++n;
  }
  EXPECT_EQ(n + once->dropped(), 3);
  EXPECT_THROW(OpenFrameSource("synth:kick?camera=nobody"), Error);
  EXPECT_THROW(OpenFrameSource("synth:kick?colour=red"), Error);
  EXPECT_THROW(OpenFrameSource("synth:no-such-preset"), Error);
}

TEST(FrameSource, UnknownSchemesAndMissingDevicesAreOneLineErrors) {
  for (const std::string spec :
       {"ftp://host/video.avi", "v4l2:/dev/video-none", "camera:x", "/no/such/file.avi"}) {
    SCOPED_TRACE(spec);
    try {
      OpenFrameSource(spec);
      ADD_FAILURE() << "opened";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos);
      EXPECT_NE(what.find(spec.substr(0, 6)), std::string::npos) << what;
    }
  }
}

TEST(FrameSource, GStreamerPipeline) {
  const auto backends = FrameSourceBackends();
  if (std::find(backends.begin(), backends.end(), "gstreamer") == backends.end()) {
    GTEST_SKIP() << "this OpenCV has no GStreamer backend";
  }
  std::unique_ptr<FrameSource> src;
  try {
    src = OpenFrameSource(
        "gst:videotestsrc num-buffers=3 ! video/x-raw,width=64,height=48,framerate=30/1");
  } catch (const Error& e) {
    GTEST_SKIP() << "GStreamer's videotestsrc is not usable here (gstreamer1.0-plugins-base "
                    "installed?): "
                 << e.what();
  }
  EXPECT_EQ(src->FrameSize(), cv::Size(64, 48));
  SourceFrame f;
  int n = 0;
  while (src->ReadFrame(&f)) {
    EXPECT_TRUE(f.origin == TimeOrigin::kContainer || f.origin == TimeOrigin::kArrival);
    ++n;
  }
  EXPECT_EQ(n, 3);
}

// The device of the kernel's vivid test driver, or "" (it must be loaded: `modprobe vivid`).
std::string VividDevice(std::string* why) {
  const std::filesystem::path sys = "/sys/class/video4linux";
  if (!std::filesystem::exists(sys)) {
    *why =
        "no V4L2 devices on this machine (/sys/class/video4linux absent; `modprobe vivid` "
        "needs a kernel with the vivid module and the right to load it)";
    return "";
  }
  for (const auto& e : std::filesystem::directory_iterator(sys)) {
    std::ifstream in(e.path() / "name");
    std::string name;
    std::getline(in, name);
    if (name.find("vivid") != std::string::npos && name.find("vid-cap") != std::string::npos) {
      return "/dev/" + e.path().filename().string();
    }
  }
  *why = "no vivid capture device loaded (`sudo modprobe vivid`)";
  return "";
}

TEST(FrameSource, V4l2WithTheVividDriver) {
  std::string why;
  const std::string device = VividDevice(&why);
  if (device.empty()) GTEST_SKIP() << why;
  FrameSourceOptions o;
  o.width = 640;
  o.height = 360;
  auto src = OpenFrameSource("v4l2:" + device, o);
  EXPECT_TRUE(src->live());
  SourceFrame f;
  double last = 0;
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(src->ReadFrame(&f));
    EXPECT_FALSE(f.bgr.empty());
    EXPECT_TRUE(f.origin == TimeOrigin::kDevice || f.origin == TimeOrigin::kArrival);
    EXPECT_NEAR(f.time_s, SystemClockNow(), 1.0);
    if (k > 0) EXPECT_GT(f.time_s, last);
    last = f.time_s;
  }
}

TEST(FrameSource, AravisSimulatedCamera) {
  const auto backends = FrameSourceBackends();
  if (std::find(backends.begin(), backends.end(), "aravis") == backends.end()) {
    GTEST_SKIP() << "built without Aravis (libaravis-dev not found)";
  }
  FrameSourceOptions o;
  o.width = 64;
  o.height = 48;
  o.fps = 100;
  o.exposure_us = 2000;
  auto src = OpenFrameSource("aravis:Fake_1", o);
  EXPECT_EQ(src->FrameSize(), cv::Size(64, 48));
  SourceFrame f;
  double last = 0;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(src->ReadFrame(&f));
    EXPECT_EQ(f.bgr.size(), cv::Size(64, 48));
    if (k > 0) EXPECT_GT(f.time_s, last);
    last = f.time_s;
  }
}

}  // namespace
}  // namespace fv::io
