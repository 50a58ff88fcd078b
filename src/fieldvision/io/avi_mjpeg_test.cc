// The Motion-JPEG AVI reader: the frames and headers OpenCV's FFmpeg reader gives for AVIs
// written by FFmpeg and by OpenCV's own MJPG writer; hand-made AVIs with an audio stream, 'rec '
// groups, odd chunk sizes and an OpenDML extension; what it leaves to OpenCV; files cut short.
#include "fieldvision/io/avi_mjpeg.h"

#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/io/io_testing.h"
#include "fieldvision/util/testing.h"

namespace fv::io {
namespace {

std::vector<std::vector<uint8_t>> FfmpegPackets(const std::string& path, double* fps,
                                                double* count) {
  cv::VideoCapture cap(path, cv::CAP_FFMPEG);
  EXPECT_TRUE(cap.isOpened());
  *fps = cap.get(cv::CAP_PROP_FPS);
  *count = cap.get(cv::CAP_PROP_FRAME_COUNT);
  EXPECT_TRUE(cap.set(cv::CAP_PROP_FORMAT, -1));
  std::vector<std::vector<uint8_t>> out;
  cv::Mat packet;
  while (cap.read(packet) && !packet.empty()) {
    out.emplace_back(packet.ptr<uint8_t>(), packet.ptr<uint8_t>() + packet.total());
  }
  return out;
}

std::vector<std::vector<uint8_t>> AllFrames(AviMjpegReader& r) {
  std::vector<std::vector<uint8_t>> out;
  std::vector<uint8_t> jpeg;
  while (r.Next(&jpeg)) out.push_back(jpeg);
  return out;
}

TEST(AviMjpeg, SameFramesAndHeadersAsFfmpegForBothWriters) {
  const std::string dir = testing::TempDir();
  cv::RNG rng(11);
  for (const int api : {cv::CAP_FFMPEG, cv::CAP_OPENCV_MJPEG}) {
    SCOPED_TRACE(api == cv::CAP_FFMPEG ? "FFmpeg's writer" : "OpenCV's MJPG writer");
    const std::string path = dir + "/v" + std::to_string(api) + ".avi";
    {
      cv::VideoWriter w(path, api, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 59.94,
                        cv::Size(96, 64));
      ASSERT_TRUE(w.isOpened());
      for (int i = 0; i < 7; ++i) {
        cv::Mat m(64, 96, CV_8UC3);
        rng.fill(m, cv::RNG::UNIFORM, 0, 256);
        w.write(m);
      }
    }
    double fps = 0, count = 0;
    const auto expected = FfmpegPackets(path, &fps, &count);
    ASSERT_EQ(expected.size(), 7u);
    auto r = AviMjpegReader::Open(path);
    ASSERT_NE(r, nullptr);
    EXPECT_NEAR(r->fps(), fps, 1e-6);
    EXPECT_EQ(r->frame_count(), static_cast<long long>(count));
    EXPECT_EQ(r->width(), 96);
    EXPECT_EQ(r->height(), 64);
    const auto frames = AllFrames(*r);
    ASSERT_EQ(frames.size(), expected.size());
    for (size_t i = 0; i < frames.size(); ++i) {
      EXPECT_EQ(frames[i], expected[i]) << "frame " << i;
      EXPECT_EQ(cv::imdecode(frames[i], cv::IMREAD_COLOR).size(), cv::Size(96, 64));
    }
  }
}

// A minimal AVI, chunk by chunk.
struct AviBuilder {
  std::string bytes;
  void U32(uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<char>(v >> (8 * i) & 255));
  }
  void Tag(const char* t) { bytes.append(t, 4); }
  size_t Open(const char* id, const char* type) {  // RIFF or LIST; returns where its size is
    Tag(id);
    const size_t at = bytes.size();
    U32(0);
    Tag(type);
    return at;
  }
  void Close(size_t at) {
    const uint32_t size = static_cast<uint32_t>(bytes.size() - at - 4);
    for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<char>(size >> (8 * i) & 255);
  }
  void Chunk(const char* id, const std::string& data) {
    Tag(id);
    U32(static_cast<uint32_t>(data.size()));
    bytes += data;
    if (data.size() & 1) bytes.push_back('\0');
  }
  static std::string Words(std::initializer_list<uint32_t> w) {
    AviBuilder b;
    for (uint32_t v : w) b.U32(v);
    return b.bytes;
  }
  void StreamList(const char* type, const char* handler, uint32_t scale, uint32_t rate,
                  uint32_t length, const char* compression) {
    const size_t strl = Open("LIST", "strl");
    uint32_t t, h;
    std::memcpy(&t, type, 4);
    std::memcpy(&h, handler, 4);
    Chunk("strh", Words({t, h, 0, 0, 0, scale, rate, 0, length, 0, 0, 0, 0, 0}));
    uint32_t c;
    std::memcpy(&c, compression, 4);
    Chunk("strf", Words({40, 32, 16, 0x180001, c, 0, 0, 0, 0, 0}));
    Close(strl);
  }
};

std::string WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

TEST(AviMjpeg, AudioRecGroupsOddSizesAndOpenDmlExtension) {
  AviBuilder b;
  const size_t riff = b.Open("RIFF", "AVI ");
  const size_t hdrl = b.Open("LIST", "hdrl");
  b.Chunk("avih", AviBuilder::Words({40000, 0, 0, 0, 2, 0, 2, 0, 32, 16, 0, 0, 0, 0}));
  b.StreamList("auds", "\0\0\0\0", 1, 48000, 0, "\1\0\0\0");
  b.StreamList("vids", "MJPG", 1, 25, 4, "MJPG");
  b.Close(hdrl);
  b.Chunk("JUNK", std::string(13, 'j'));
  const size_t movi = b.Open("LIST", "movi");
  b.Chunk("00wb", "sound");
  b.Chunk("01dc", "frame0");
  const size_t rec = b.Open("LIST", "rec ");
  b.Chunk("00wb", "more sound");
  b.Chunk("01dc", "frame1-odd");  // 10 bytes
  b.Chunk("01dc", "odd");         // padded to 4
  b.Close(rec);
  b.Chunk("ix01", "index");
  b.Close(movi);
  b.Chunk("idx1", std::string(16, '\0'));
  b.Close(riff);
  const size_t avix = b.Open("RIFF", "AVIX");
  const size_t movi2 = b.Open("LIST", "movi");
  b.Chunk("01db", "frame3");
  b.Close(movi2);
  b.Close(avix);
  const std::string path = WriteFile(testing::TempDir() + "/made.avi", b.bytes);
  auto r = AviMjpegReader::Open(path);
  ASSERT_NE(r, nullptr);
  EXPECT_DOUBLE_EQ(r->fps(), 25.0);
  EXPECT_EQ(r->frame_count(), 4);
  EXPECT_EQ(r->width(), 32);
  const auto frames = AllFrames(*r);
  ASSERT_EQ(frames.size(), 4u);
  const char* expected[] = {"frame0", "frame1-odd", "odd", "frame3"};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(std::string(frames[i].begin(), frames[i].end()), expected[i]) << "frame " << i;
  }
}

TEST(AviMjpeg, LeavesOtherFilesToOpenCv) {
  const std::string dir = testing::TempDir();
  AviBuilder xvid;
  const size_t riff = xvid.Open("RIFF", "AVI ");
  const size_t hdrl = xvid.Open("LIST", "hdrl");
  xvid.StreamList("vids", "XVID", 1, 25, 1, "XVID");
  xvid.Close(hdrl);
  const size_t movi = xvid.Open("LIST", "movi");
  xvid.Chunk("00dc", "not a jpeg");
  xvid.Close(movi);
  xvid.Close(riff);
  AviBuilder wave;
  wave.Close(wave.Open("RIFF", "WAVE"));
  for (const auto& [name, bytes] :
       std::vector<std::pair<std::string, std::string>>{{"xvid.avi", xvid.bytes},
                                                        {"wave.avi", wave.bytes},
                                                        {"empty.avi", ""},
                                                        {"text.avi", "this is not a video at all"},
                                                        {"cut.avi", xvid.bytes.substr(0, 30)}}) {
    SCOPED_TRACE(name);
    EXPECT_EQ(AviMjpegReader::Open(WriteFile(fmt::format("{}/{}", dir, name), bytes)), nullptr);
  }
  EXPECT_EQ(AviMjpegReader::Open(dir + "/missing.avi"), nullptr);
}

TEST(AviMjpeg, FileCutShortEndsTheFramesWhereItEnds) {
  const std::string dir = testing::TempDir();
  auto whole = AviMjpegReader::Open(test_util::WriteTruncatedMjpg(dir + "/whole.avi", 1.0));
  ASSERT_NE(whole, nullptr);
  const auto all = AllFrames(*whole);
  ASSERT_EQ(all.size(), 16u);
  auto cut = AviMjpegReader::Open(test_util::WriteTruncatedMjpg(dir + "/cut.avi", 0.5));
  ASSERT_NE(cut, nullptr);
  EXPECT_EQ(cut->frame_count(), 16);  // as the header announces
  const auto some = AllFrames(*cut);
  EXPECT_GE(some.size(), 6u);
  EXPECT_LE(some.size(), 8u);
  for (size_t i = 0; i < some.size(); ++i) EXPECT_EQ(some[i], all[i]) << "frame " << i;
}

}  // namespace
}  // namespace fv::io
