// The codecs plugin: loaded only when first needed, and each function as OpenCV's.
#include "fieldvision/codecs/codecs.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "fieldvision/util/testing.h"

namespace fv::codecs {
namespace {

bool Mapped(const std::string& library) {
  std::ifstream maps("/proc/self/maps");
  const std::string all((std::istreambuf_iterator<char>(maps)), std::istreambuf_iterator<char>());
  return all.find(library) != std::string::npos;
}

// In a child process (this one may have loaded the plugin already): OpenCV's imgcodecs and
// videoio are not mapped until the first call, and are after it.
TEST(Codecs, PluginLoadsOnFirstUseOnly) {
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    int code = 0;
    if (Mapped("libopencv_videoio") || Mapped("libopencv_imgcodecs")) code |= 1;
    std::vector<uchar> buf;
    if (!ImEncode(".png", cv::Mat(4, 4, CV_8UC3, cv::Scalar(1, 2, 3)), &buf)) code |= 2;
    if (!Mapped("libopencv_videoio") || !Mapped("libopencv_imgcodecs")) code |= 4;
    _exit(code);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0)
      << "1: mapped before use, 2: encode failed, 4: not mapped after";
}

TEST(Codecs, ImagesRoundTrip) {
  cv::Mat image(24, 32, CV_8UC3);
  cv::randu(image, 0, 256);
  std::vector<uchar> png;
  ASSERT_TRUE(ImEncode(".png", image, &png));
  EXPECT_EQ(cv::norm(ImDecode(png, cv::IMREAD_COLOR), image, cv::NORM_INF), 0);
  const std::string path = testing::TempDir() + "/a.png";
  ASSERT_TRUE(ImWrite(path, image));
  EXPECT_EQ(cv::norm(ImRead(path), image, cv::NORM_INF), 0);
  EXPECT_EQ(ImRead(path, cv::IMREAD_GRAYSCALE).channels(), 1);
  std::vector<uchar> jpeg;
  ASSERT_TRUE(ImEncode(".jpg", image, &jpeg, {cv::IMWRITE_JPEG_QUALITY, 95}));
  EXPECT_EQ(ImDecode(jpeg).size(), image.size());
  EXPECT_TRUE(ImRead(testing::TempDir() + "/missing.png").empty());
  EXPECT_TRUE(ImDecode(std::vector<uchar>{1, 2, 3}).empty());
  EXPECT_FALSE(ImWrite(testing::TempDir() + "/no-such-folder/a.png", image));
}

// Damaged images give empty images and nothing on stderr (libpng and libjpeg print there), also
// from several threads at once; stderr works again afterwards.
TEST(Codecs, DamagedImagesAreQuiet) {
  cv::Mat image(40, 60, CV_8UC3);
  cv::randu(image, 0, 256);
  std::vector<uchar> png, jpeg;
  ASSERT_TRUE(ImEncode(".png", image, &png));
  ASSERT_TRUE(ImEncode(".jpg", image, &jpeg));
  const std::string dir = testing::TempDir();
  const std::vector<uchar> cut_png(png.begin(), png.begin() + png.size() / 2);
  const std::vector<uchar> cut_jpeg(jpeg.begin(), jpeg.begin() + jpeg.size() / 2);
  {
    std::ofstream(dir + "/cut.png", std::ios::binary)
        .write(reinterpret_cast<const char*>(cut_png.data()), std::streamsize(cut_png.size()));
    std::ofstream(dir + "/cut.jpg", std::ios::binary)
        .write(reinterpret_cast<const char*>(cut_jpeg.data()), std::streamsize(cut_jpeg.size()));
  }
  ::testing::internal::CaptureStderr();
  EXPECT_TRUE(ImRead(dir + "/cut.png").empty());
  EXPECT_FALSE(ImRead(dir + "/cut.jpg").empty());  // decoded as far as it goes
  EXPECT_TRUE(ImDecode(cut_png).empty());
  std::vector<std::thread> threads;
  threads.reserve(4);
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < 20; ++i) {
        EXPECT_TRUE(ImRead(dir + "/cut.png").empty());
        EXPECT_FALSE(ImDecode(png).empty());
      }
    });
  }
  for (auto& t : threads) t.join();
  std::fputs("after\n", stderr);
  std::fflush(stderr);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "after\n");
}

TEST(Codecs, VideoWrittenAndReadBack) {
  EXPECT_EQ(FourCc('M', 'J', 'P', 'G'), 0x47504A4D);
  EXPECT_TRUE(HasVideoBackend(cv::CAP_FFMPEG));
  const std::string path = testing::TempDir() + "/v.avi";
  {
    auto writer = NewVideoWriter();
    ASSERT_FALSE(writer->isOpened());
    ASSERT_TRUE(OpenVideoWriter(writer.get(), path, cv::CAP_OPENCV_MJPEG,
                                FourCc('M', 'J', 'P', 'G'), 25, cv::Size(64, 48)));
    for (int i = 0; i < 5; ++i) writer->write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(40 * i, 0, 0)));
  }
  auto capture = NewVideoCapture();
  EXPECT_EQ(BackendName(*capture), "");
  ASSERT_TRUE(capture->open(path, cv::CAP_FFMPEG));
  EXPECT_EQ(BackendName(*capture), "FFMPEG");
  EXPECT_EQ(capture->get(cv::CAP_PROP_FRAME_COUNT), 5);
  int frames = 0;
  cv::Mat frame;
  while (capture->read(frame)) {
    EXPECT_NEAR(frame.at<cv::Vec3b>(10, 10)[0], 40 * frames, 3);
    ++frames;
  }
  EXPECT_EQ(frames, 5);
}

}  // namespace
}  // namespace fv::codecs
