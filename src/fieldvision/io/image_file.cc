#include "fieldvision/io/image_file.h"

#include <opencv2/imgcodecs.hpp>

#include "fieldvision/util/error.h"

namespace fv {

void WriteImage(const std::string& path, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = cv::imwrite(path, image);
  } catch (const cv::Exception&) {
    ok = false;
  }
  FV_REQUIRE(ok, "cannot write image '{}' (check the folder and the extension)", path);
}

}  // namespace fv
