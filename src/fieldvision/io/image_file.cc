#include "fieldvision/io/image_file.h"

#include <fstream>
#include <iterator>
#include <vector>

#include "fieldvision/codecs/codecs.h"
#include "fieldvision/io/jpeg_orientation.h"
#include "fieldvision/io/jpeg_region.h"
#include "fieldvision/util/error.h"

namespace fv::io {
namespace {

// The JPEG at `path` decoded by libjpeg-turbo; empty when it is no JPEG, needs turning or does
// not decode (cv::imread then has its say). Data that ends early is decoded as far as it goes,
// as cv::imread does, without libjpeg's message on stderr.
cv::Mat TryDecodeJpeg(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  char magic[2] = {0, 0};
  if (!in.read(magic, 2) || static_cast<uint8_t>(magic[0]) != 0xFF ||
      static_cast<uint8_t>(magic[1]) != 0xD8) {
    return {};
  }
  std::vector<uint8_t> bytes = {0xFF, 0xD8};
  bytes.insert(bytes.end(), std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (JpegOrientation(bytes.data(), bytes.size()) != 1) return {};
  cv::Mat bgr;
  try {
    JpegRegionDecoder().Decode(bytes.data(), bytes.size(), cv::Rect(), &bgr, path);
  } catch (const Error&) {
    return {};
  }
  return bgr;
}

}  // namespace

cv::Mat TryReadImage(const std::string& path) {
  cv::Mat image = TryDecodeJpeg(path);
  if (!image.empty()) return image;
  try {
    image = codecs::ImRead(path, cv::IMREAD_COLOR);
  } catch (const cv::Exception&) {
    image.release();
  }
  return image;
}

cv::Mat ReadImage(const std::string& path) {
  cv::Mat image = TryReadImage(path);
  FV_REQUIRE(!image.empty(), "cannot read image '{}' (missing, unreadable or not an image)", path);
  return image;
}

void WriteImage(const std::string& path, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = codecs::ImWrite(path, image);
  } catch (const cv::Exception&) {
    ok = false;
  }
  FV_REQUIRE(ok, "cannot write image '{}' (check the folder and the extension)", path);
}

}  // namespace fv::io
