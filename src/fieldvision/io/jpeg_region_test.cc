#include "fieldvision/io/jpeg_region.h"

#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/io/io_testing.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::io {
namespace {

// A textured, noisy colour image (sharp edges, gradients) as JPEG bytes.
std::vector<uint8_t> TestJpeg(util::Rng& rng, int w, int h, cv::Mat* image = nullptr) {
  cv::Mat img(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      img.at<cv::Vec3b>(y, x) =
          cv::Vec3b(static_cast<uint8_t>((x * 3) % 256), static_cast<uint8_t>((y * 2) % 256),
                    static_cast<uint8_t>(rng.UniformInt(0, 255)));
    }
  }
  cv::circle(img, {w / 3, h / 2}, h / 5, cv::Scalar(0, 110, 255), cv::FILLED);
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", img, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
  if (image) *image = img;
  return jpeg;
}

// A header announcing far more pixels than the data can hold (60000 x 60000 from 2 KB: a damaged
// or crafted file) is an error before anything is allocated, not gigabytes of grey.
TEST(JpegRegionDecoder, HeaderLargerThanItsDataIsAnError) {
  testing::SeededRng rng(37);
  std::vector<uint8_t> jpeg = TestJpeg(rng, 64, 48);
  ASSERT_TRUE(test_util::SetJpegHeaderSize(&jpeg, 60000, 60000));
  EXPECT_EQ(JpegRegionDecoder::ReadSize(jpeg.data(), jpeg.size(), "big.jpg"),
            cv::Size(60000, 60000));
  cv::Mat bgr;
  const std::string error = testing::ErrorOf(
      [&] { JpegRegionDecoder().Decode(jpeg.data(), jpeg.size(), cv::Rect(), &bgr, "big.jpg"); });
  EXPECT_NE(error.find("big.jpg: the header announces 60000x60000 pixels"), std::string::npos)
      << error;
  EXPECT_TRUE(bgr.empty());
}

TEST(JpegRegionDecoder, WholeImageAndRegionsMatchAFullDecode) {
  testing::SeededRng rng(31);
  const std::vector<uint8_t> jpeg = TestJpeg(rng, 333, 250);
  EXPECT_EQ(JpegRegionDecoder::ReadSize(jpeg.data(), jpeg.size(), "t.jpg"), cv::Size(333, 250));
  JpegRegionDecoder dec;
  cv::Mat full;
  const cv::Rect all = dec.Decode(jpeg.data(), jpeg.size(), cv::Rect(), &full, "t.jpg");
  EXPECT_EQ(all, cv::Rect(0, 0, 333, 250));
  // The same pixels as OpenCV's decoder (libjpeg-turbo with the same settings).
  const cv::Mat ref = cv::imdecode(jpeg, cv::IMREAD_COLOR);
  EXPECT_EQ(cv::norm(full, ref, cv::NORM_INF), 0.0);
  // Random regions, then columns 1-3 wide at both edges and inside (a crop that narrow was
  // upsampled wrongly at the left edge).
  std::vector<cv::Rect> regions;
  for (int trial = 0; trial < 40; ++trial) {
    const int x = rng.UniformInt(-20, 320), y = rng.UniformInt(-20, 240);
    regions.emplace_back(x, y, rng.UniformInt(1, 120), rng.UniformInt(1, 120));
  }
  for (int w = 1; w <= 3; ++w) {
    for (int x : {0, 333 - w, 100, 17}) regions.emplace_back(x, 40, w, 90);
  }
  for (const cv::Rect& want : regions) {
    const cv::Rect clipped = want & cv::Rect(0, 0, 333, 250);
    if (clipped.empty()) continue;
    cv::Mat part(250, 333, CV_8UC3, cv::Scalar(7, 7, 7));
    const cv::Rect got = dec.Decode(jpeg.data(), jpeg.size(), want, &part, "t.jpg");
    EXPECT_EQ(got & clipped, clipped) << "asked " << want << " got " << got;
    EXPECT_EQ(cv::norm(part(got), full(got), cv::NORM_INF), 0.0) << got;
    // Nothing beyond the decoded rectangle (and the approximate column on each side) changes.
    cv::Mat outside = part.clone();
    const cv::Rect written =
        cv::Rect(got.x - 1, got.y, got.width + 2, got.height) & cv::Rect(0, 0, 333, 250);
    outside(written).setTo(cv::Scalar(7, 7, 7));
    EXPECT_EQ(cv::countNonZero(outside.reshape(1) != 7), 0) << got;
  }
  EXPECT_EQ(dec.warnings(), 0);
}

TEST(JpegRegionDecoder, DamagedDataIsCountedOrAnErrorNamingTheInput) {
  testing::SeededRng rng(32);
  std::vector<uint8_t> jpeg = TestJpeg(rng, 160, 120);
  JpegRegionDecoder dec;
  cv::Mat img;
  // Data that ends early: decoded as far as it goes, with a warning.
  std::vector<uint8_t> cut(jpeg.begin(), jpeg.begin() + jpeg.size() * 2 / 3);
  EXPECT_NO_THROW(dec.Decode(cut.data(), cut.size(), cv::Rect(), &img, "cut.jpg"));
  EXPECT_GT(dec.warnings(), 0);
  auto error_of = [&](const std::vector<uint8_t>& data) {
    try {
      dec.Decode(data.data(), data.size(), cv::Rect(), &img, "cam2.avi frame 17");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string not_jpeg = error_of({'R', 'I', 'F', 'F', 0, 0, 0, 0});
  EXPECT_NE(not_jpeg.find("cam2.avi frame 17"), std::string::npos) << not_jpeg;
  std::vector<uint8_t> header_only(jpeg.begin(), jpeg.begin() + 4);
  const std::string broken = error_of(header_only);
  EXPECT_NE(broken.find("cam2.avi frame 17"), std::string::npos) << broken;
  EXPECT_EQ(broken.find('\n'), std::string::npos);
  // A region outside the image is a contract violation.
  EXPECT_THROW(dec.Decode(jpeg.data(), jpeg.size(), cv::Rect(500, 500, 10, 10), &img, "t"), Error);
}

}  // namespace
}  // namespace fv::io
