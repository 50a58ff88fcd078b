#include "fieldvision/io/image_file.h"

#include "fieldvision/codecs/codecs.h"
#include "fieldvision/util/error.h"

namespace fv::io {

cv::Mat ReadImage(const std::string& path) {
  cv::Mat image;
  try {
    image = codecs::ImRead(path, cv::IMREAD_COLOR);
  } catch (const cv::Exception&) {
    image.release();
  }
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
