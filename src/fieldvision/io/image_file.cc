#include "fieldvision/io/image_file.h"

#include <fstream>
#include <iterator>
#include <vector>

#include "fieldvision/codecs/codecs.h"
#include "fieldvision/io/jpeg_orientation.h"
#include "fieldvision/io/jpeg_region.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::io {
namespace {

enum class JpegRead { kDecoded, kNotDecoded, kDamaged };

// The JPEG at `path` decoded by libjpeg-turbo into *bgr: kNotDecoded when it is no JPEG, needs
// turning or does not decode (cv::imread then has its say); kDamaged when its header announces
// more pixels than its data can hold (cv::imread would allocate and fill them all, up to 1 Gpx).
// Data that ends early is decoded as far as it goes, as cv::imread does, without libjpeg's
// message on stderr.
JpegRead TryDecodeJpeg(const std::string& path, cv::Mat* bgr) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return JpegRead::kNotDecoded;
  char magic[2] = {0, 0};
  if (!in.read(magic, 2) || static_cast<uint8_t>(magic[0]) != 0xFF ||
      static_cast<uint8_t>(magic[1]) != 0xD8) {
    return JpegRead::kNotDecoded;
  }
  std::vector<uint8_t> bytes = {0xFF, 0xD8};
  bytes.insert(bytes.end(), std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  try {
    const cv::Size size = JpegRegionDecoder::ReadSize(bytes.data(), bytes.size(), path);
    if (!JpegRegionDecoder::CanHold(bytes.size(), size)) return JpegRead::kDamaged;
    if (JpegOrientation(bytes.data(), bytes.size()) != 1) return JpegRead::kNotDecoded;
    JpegRegionDecoder().Decode(bytes.data(), bytes.size(), cv::Rect(), bgr, path);
  } catch (const Error&) {
    return JpegRead::kNotDecoded;
  }
  return JpegRead::kDecoded;
}

}  // namespace

cv::Mat TryReadImage(const std::string& path) {
  cv::Mat image;
  const JpegRead jpeg = TryDecodeJpeg(path, &image);
  if (jpeg == JpegRead::kDecoded) return image;
  if (jpeg == JpegRead::kDamaged) return {};
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
  // Beside the path, renamed over it when whole: a failed write leaves an earlier image.
  util::AtomicWrite(
      path,
      [&](const std::string& temp_path) {
        bool ok = false;
        try {
          ok = codecs::ImWrite(temp_path, image);
        } catch (const cv::Exception&) {
          ok = false;
        }
        FV_REQUIRE(ok, "cannot write image '{}' (check the folder and the extension)", temp_path);
      },
      "image");
}

}  // namespace fv::io
