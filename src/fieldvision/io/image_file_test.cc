#include "fieldvision/io/image_file.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/io/frame_source.h"
#include "fieldvision/io/io_testing.h"
#include "fieldvision/io/jpeg_orientation.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::io {
namespace {

namespace fs = std::filesystem;

cv::Mat NoisyImage(util::Rng& rng, int w, int h) {
  cv::Mat img(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>((x * 5) % 256),
                                          static_cast<uint8_t>(rng.UniformInt(0, 255)),
                                          static_cast<uint8_t>((y * 3) % 256));
    }
  }
  cv::circle(img, {w / 2, h / 3}, h / 4, cv::Scalar(20, 215, 245), cv::FILLED);
  return img;
}

void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

// An APP1 "Exif" segment holding IFD0 with one entry, the orientation, in either byte order.
std::vector<uint8_t> ExifApp1(int orientation, bool little) {
  std::vector<uint8_t> tiff;
  auto u16 = [&](unsigned v) {
    if (little) {
      tiff.push_back(v & 0xFF);
      tiff.push_back(v >> 8);
    } else {
      tiff.push_back(v >> 8);
      tiff.push_back(v & 0xFF);
    }
  };
  auto u32 = [&](uint32_t v) {
    if (little) {
      u16(v & 0xFFFF);
      u16(v >> 16);
    } else {
      u16(v >> 16);
      u16(v & 0xFFFF);
    }
  };
  tiff.push_back(little ? 'I' : 'M');
  tiff.push_back(little ? 'I' : 'M');
  u16(42);
  u32(8);       // IFD0 right after the header
  u16(2);       // two entries: another tag, then the orientation
  u16(0x010F);  // Make, ASCII, 4 bytes inline
  u16(2);
  u32(4);
  u32(0x41424300);
  u16(0x0112);
  u16(3);  // SHORT
  u32(1);
  u16(static_cast<unsigned>(orientation));
  u16(0);
  u32(0);  // no next IFD
  std::vector<uint8_t> seg = {0xFF, 0xE1, 0, 0, 'E', 'x', 'i', 'f', 0, 0};
  for (const uint8_t b : tiff) seg.push_back(b);
  const size_t length = seg.size() - 2;
  seg[2] = static_cast<uint8_t>(length >> 8);
  seg[3] = static_cast<uint8_t>(length & 0xFF);
  return seg;
}

// `jpeg` with `segment` inserted right after its SOI marker.
std::vector<uint8_t> WithSegment(const std::vector<uint8_t>& jpeg,
                                 const std::vector<uint8_t>& seg) {
  std::vector<uint8_t> out = {jpeg[0], jpeg[1]};
  for (const uint8_t b : seg) out.push_back(b);
  for (size_t i = 2; i < jpeg.size(); ++i) out.push_back(jpeg[i]);
  return out;
}

TEST(JpegOrientation, ReadsTheTagInEitherByteOrderAndIgnoresTheRest) {
  testing::SeededRng rng(3);
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", NoisyImage(rng, 64, 48), jpeg);
  EXPECT_EQ(JpegOrientation(jpeg.data(), jpeg.size()), 1);
  for (int o = 1; o <= 8; ++o) {
    for (bool little : {true, false}) {
      const std::vector<uint8_t> tagged = WithSegment(jpeg, ExifApp1(o, little));
      EXPECT_EQ(JpegOrientation(tagged.data(), tagged.size()), o) << "little " << little;
    }
  }
  // Out of range values, other data and every truncation: 1 or the tag, never a read past the end
  // (the sanitizer build checks the latter).
  const std::vector<uint8_t> bad = WithSegment(jpeg, ExifApp1(9, true));
  EXPECT_EQ(JpegOrientation(bad.data(), bad.size()), 1);
  const std::vector<uint8_t> tagged = WithSegment(jpeg, ExifApp1(6, false));
  for (size_t n = 0; n <= 80; ++n) {
    const std::vector<uint8_t> cut(tagged.begin(), tagged.begin() + n);
    const int o = JpegOrientation(cut.data(), cut.size());
    EXPECT_TRUE(o == 1 || o == 6) << n;
  }
  EXPECT_EQ(JpegOrientation(nullptr, 0), 1);
  const std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  EXPECT_EQ(JpegOrientation(png.data(), png.size()), 1);
}

// JPEGs (colour, grey, odd sizes) decode to exactly cv::imread's pixels; one to be turned, a PNG
// and a truncated JPEG go to cv::imread; a missing file is an error naming it.
TEST(ReadImage, SamePixelsAsImread) {
  testing::SeededRng rng(5);
  const std::string dir = testing::TempDir();
  std::vector<std::string> files;
  for (const cv::Size size : {cv::Size(64, 48), cv::Size(333, 251), cv::Size(17, 9)}) {
    const std::string path = fmt::format("{}/c{}x{}.jpg", dir, size.width, size.height);
    cv::imwrite(path, NoisyImage(rng, size.width, size.height), {cv::IMWRITE_JPEG_QUALITY, 85});
    files.push_back(path);
  }
  cv::Mat grey;
  cv::cvtColor(NoisyImage(rng, 90, 70), grey, cv::COLOR_BGR2GRAY);
  cv::imwrite(dir + "/grey.jpg", grey);
  files.push_back(dir + "/grey.jpg");
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", NoisyImage(rng, 80, 40), jpeg);
  WriteBytes(dir + "/turned.jpg", WithSegment(jpeg, ExifApp1(6, true)));
  files.push_back(dir + "/turned.jpg");
  WriteBytes(dir + "/cut.jpg", std::vector<uint8_t>(jpeg.begin(), jpeg.begin() + jpeg.size() / 2));
  files.push_back(dir + "/cut.jpg");
  cv::imwrite(dir + "/p.png", NoisyImage(rng, 40, 30));
  files.push_back(dir + "/p.png");
  for (const std::string& f : files) {
    const cv::Mat expected = cv::imread(f, cv::IMREAD_COLOR);
    const cv::Mat got = ReadImage(f);
    ASSERT_EQ(got.size(), expected.size()) << f;
    ASSERT_EQ(got.type(), CV_8UC3) << f;
    EXPECT_EQ(cv::norm(got, expected, cv::NORM_INF), 0.0) << f;
  }
  EXPECT_EQ(ReadImage(dir + "/turned.jpg").size(), cv::Size(40, 80));  // turned by 90 degrees
  EXPECT_TRUE(TryReadImage(dir + "/missing.jpg").empty());
  const std::string error = testing::ErrorOf([&] { ReadImage(dir + "/missing.jpg"); });
  EXPECT_NE(error.find("missing.jpg"), std::string::npos) << error;
}

// An image sequence kept encoded delivers a still to be turned decoded and turned (as its
// size, from cv::imread, says), the others encoded.
TEST(ReadImage, EncodedSequenceTurnsStillsAsImread) {
  testing::SeededRng rng(7);
  const std::string dir = testing::TempDir();
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", NoisyImage(rng, 80, 40), jpeg);
  fs::create_directories(dir + "/turned");
  fs::create_directories(dir + "/plain");
  // Numbered from 7 (a clip cut out of a longer one): as from 0, and as OpenCV's reader starts.
  for (int i = 7; i < 9; ++i) {
    WriteBytes(fmt::format("{}/turned/{:05d}.jpg", dir, i), WithSegment(jpeg, ExifApp1(6, i == 7)));
    WriteBytes(fmt::format("{}/plain/{:05d}.jpg", dir, i), jpeg);
  }
  FrameSourceOptions o;
  o.encoded = true;
  auto turned = OpenFrameSource(dir + "/turned/%05d.jpg", o);
  auto plain = OpenFrameSource(dir + "/plain/%05d.jpg", o);
  EXPECT_EQ(turned->FrameSize(), cv::Size(40, 80));
  EXPECT_EQ(plain->FrameSize(), cv::Size(80, 40));
  const cv::Mat expected = cv::imread(dir + "/turned/00007.jpg", cv::IMREAD_COLOR);
  SourceFrame f;
  int n = 0;
  while (turned->ReadFrame(&f)) {
    EXPECT_TRUE(f.jpeg.empty());
    ASSERT_EQ(f.bgr.size(), cv::Size(40, 80));
    EXPECT_EQ(cv::norm(f.bgr, expected, cv::NORM_INF), 0.0);
    ++n;
  }
  EXPECT_EQ(n, 2);
  ASSERT_TRUE(plain->ReadFrame(&f));
  EXPECT_EQ(f.jpeg, jpeg);
}

// A JPEG whose header announces 30000 x 30000 pixels (within OpenCV's 2^30 limit) over a few
// hundred bytes is damaged: not decoded, nor given to cv::imread, which would fill 2.7 GB; with
// an EXIF orientation (cv::imread's case) the same.
TEST(ReadImage, AHeaderAnnouncingMorePixelsThanItsDataHoldsIsDamaged) {
  testing::SeededRng rng(11);
  const std::string dir = testing::TempDir();
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", NoisyImage(rng, 16, 16), jpeg);
  ASSERT_TRUE(test_util::SetJpegHeaderSize(&jpeg, 30000, 30000));
  WriteBytes(dir + "/huge.jpg", jpeg);
  WriteBytes(dir + "/huge_turned.jpg", WithSegment(jpeg, ExifApp1(6, true)));
  EXPECT_TRUE(TryReadImage(dir + "/huge.jpg").empty());
  EXPECT_TRUE(TryReadImage(dir + "/huge_turned.jpg").empty());
  EXPECT_THROW(ReadImage(dir + "/huge.jpg"), Error);
}

// The real photos (../shared/data): libjpeg-turbo's pixels are cv::imread's.
TEST(ReadImage, RealPhotosDecodeAsImread) {
  const std::string data = testing::SharedDataDir();
  const fs::path photos = fs::path(data) / "robocup-ball-photos";
  if (data.empty() || !fs::is_directory(photos)) GTEST_SKIP() << "no shared photos";
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(photos)) {
    if (e.path().extension() != ".jpg") continue;
    ++n;
    const cv::Mat expected = cv::imread(e.path().string(), cv::IMREAD_COLOR);
    const cv::Mat got = ReadImage(e.path().string());
    ASSERT_EQ(got.size(), expected.size()) << e.path();
    EXPECT_EQ(cv::norm(got, expected, cv::NORM_INF), 0.0) << e.path();
  }
  EXPECT_GT(n, 500);
}

// A write that fails (here: an empty image) leaves an earlier image as it was, and no temporary
// file beside it; one that succeeds replaces it.
TEST(WriteImage, AFailedWriteLeavesAnEarlierImage) {
  const std::string dir = testing::TempDir();
  const std::string path = dir + "/map.png";
  const cv::Mat earlier(8, 8, CV_8UC3, cv::Scalar(10, 20, 30));
  WriteImage(path, earlier);
  const std::string message = testing::ErrorOf([&] { WriteImage(path, cv::Mat()); });
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_EQ(cv::norm(ReadImage(path), earlier, cv::NORM_INF), 0);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                          std::filesystem::directory_iterator()),
            1);
  const cv::Mat later(8, 8, CV_8UC3, cv::Scalar(200, 100, 0));
  WriteImage(path, later);
  EXPECT_EQ(cv::norm(ReadImage(path), later, cv::NORM_INF), 0);
}

}  // namespace
}  // namespace fv::io
