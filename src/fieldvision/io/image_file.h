// Reading and writing single images (frames, maps, overlays, pictures): cv::imread/imwrite with a
// one-line fv::Error that names the path.
#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace fv::io {

// An 8-bit BGR image; throws fv::Error naming `path` when it is missing or does not decode.
cv::Mat ReadImage(const std::string& path);

// Throws fv::Error naming `path` when the image cannot be written.
void WriteImage(const std::string& path, const cv::Mat& image);

}  // namespace fv::io
