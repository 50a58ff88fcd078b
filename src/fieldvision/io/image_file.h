// Writing result images (maps, overlays, pictures): cv::imwrite with a one-line fv::Error that
// names the path when the folder or the extension is wrong.
#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace fv {

// Throws fv::Error naming `path` when the image cannot be written.
void WriteImage(const std::string& path, const cv::Mat& image);

}  // namespace fv
