#include "fieldvision/io/video_writer.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "fieldvision/io/video_source.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::io {
namespace {
namespace fs = std::filesystem;

std::string FirstLine(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

long Entries(const std::string& dir) {
  return std::distance(fs::directory_iterator(dir), fs::directory_iterator());
}

cv::Mat TestFrame(int i) { return cv::Mat(48, 64, CV_8UC3, cv::Scalar(20 * i, 100, 200 - 20 * i)); }

// Frames reach the path only on Close(): a run that fails before (the writer destroyed) leaves
// an existing file as it was and no temporary file beside it.
TEST(PlayableVideoWriter, AnExistingFileIsReplacedOnlyByAClosedVideo) {
  const std::string dir = testing::TempDir();
  const std::string path = dir + "/drawn.avi";
  std::ofstream(path) << "an earlier run's video";
  {
    PlayableVideoWriter w(path, 25, {64, 48});
    w.Write(TestFrame(0));
    w.Write(TestFrame(1));
  }  // a failed run: no Close()
  EXPECT_EQ(FirstLine(path), "an earlier run's video");
  EXPECT_EQ(Entries(dir), 1);
  PlayableVideoWriter w(path, 25, {64, 48});
  EXPECT_EQ(w.codec(), "MJPG");
  for (int i = 0; i < 3; ++i) w.Write(TestFrame(i));
  w.Close();
  EXPECT_EQ(w.frames(), 3);
  EXPECT_EQ(Entries(dir), 1);
  auto source = VideoSource::Open(path);
  Frame frame;
  int read = 0;
  while (source->Read(frame)) {
    EXPECT_EQ(frame.bgr.size(), cv::Size(64, 48));
    ++read;
  }
  EXPECT_EQ(read, 3);
}

// A symlink is written through (the link stays, its target gets the video); a folder is refused
// before any frame, naming it.
TEST(PlayableVideoWriter, WritesThroughASymlinkAndRefusesAFolder) {
  const std::string dir = testing::TempDir();
  std::ofstream(dir + "/real.avi") << "old";
  fs::create_symlink(dir + "/real.avi", dir + "/link.avi");
  PlayableVideoWriter w(dir + "/link.avi", 25, {64, 48});
  w.Write(TestFrame(0));
  w.Close();
  EXPECT_TRUE(fs::is_symlink(dir + "/link.avi"));
  EXPECT_NE(FirstLine(dir + "/real.avi"), "old");
  fs::create_directories(dir + "/folder.mp4");
  const std::string e = testing::ErrorOf([&] {
    PlayableVideoWriter(dir + "/folder.mp4", 25, {64, 48}, "--draw");
  });
  EXPECT_NE(e.find("--draw"), std::string::npos) << e;
  EXPECT_NE(e.find("folder.mp4"), std::string::npos) << e;
  EXPECT_EQ(FallbackVideoPath(dir + "/a.MP4"), dir + "/a.avi");
  EXPECT_EQ(FallbackVideoPath(dir + "/a.mkv"), dir + "/a.mkv");
}

// A .mp4 path gets H.264 where OpenCV's FFmpeg has an encoder, else Motion-JPEG as .avi with a
// note saying so (browsers do not play MPEG-4 Part 2 or Motion-JPEG in MP4).
TEST(PlayableVideoWriter, Mp4IsH264OrSaysWhyNot) {
  const std::string dir = testing::TempDir();
  PlayableVideoWriter w(dir + "/drawn.mp4", 10, {64, 48});
  w.Write(TestFrame(0));
  w.Close();
  if (H264Available()) {
    EXPECT_EQ(w.codec(), "H.264");
    EXPECT_EQ(w.path(), dir + "/drawn.mp4");
    EXPECT_TRUE(w.note().empty());
  } else {
    EXPECT_EQ(w.codec(), "MJPG");
    EXPECT_EQ(w.path(), dir + "/drawn.avi");
    EXPECT_NE(w.note().find("H.264"), std::string::npos) << w.note();
  }
  EXPECT_TRUE(fs::exists(w.path()));
}

TEST(PlayableVideoWriter, BadSettingsAndFramesAreErrorsNamingThePath) {
  const std::string dir = testing::TempDir();
  const auto message = [](const auto& f) { return testing::ErrorOf(f); };
  const std::string path = dir + "/v.avi";
  EXPECT_NE(message([&] { PlayableVideoWriter(path, 0, {64, 48}); }).find(path), std::string::npos);
  EXPECT_NE(message([&] { PlayableVideoWriter(path, 25, {0, 48}); }).find(path), std::string::npos);
  const std::string missing = dir + "/no/such/folder/v.avi";
  EXPECT_NE(message([&] {
              PlayableVideoWriter(missing, 25, {64, 48});
            }).find(missing),
            std::string::npos);
  for (const char* name : {"/v.jpg", "/v_%03d.png", "/v"}) {
    const std::string not_video = dir + name;
    const std::string why = message([&] { PlayableVideoWriter(not_video, 25, {64, 48}); });
    EXPECT_NE(why.find(not_video), std::string::npos) << why;
    EXPECT_NE(why.find(".mp4, .avi or .mkv"), std::string::npos) << why;
  }
  EXPECT_NO_THROW(CheckVideoPath(dir + "/V.MKV", "--draw"));
  PlayableVideoWriter w(path, 25, {64, 48});
  const std::string wrong = message([&] { w.Write(cv::Mat(10, 10, CV_8UC3)); });
  EXPECT_NE(wrong.find(path), std::string::npos) << wrong;
  EXPECT_NE(wrong.find("10x10"), std::string::npos) << wrong;
}

}  // namespace
}  // namespace fv::io
