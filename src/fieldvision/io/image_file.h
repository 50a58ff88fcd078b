// Reading and writing single images (frames, maps, overlays, pictures) with a one-line fv::Error
// that names the path. JPEG files that need no turning (EXIF orientation 1) are decoded by
// libjpeg-turbo straight into BGR (io::JpegRegionDecoder, the decoder of MJPG frames: the same
// pixels as cv::imread, without its RGB to BGR pass or loading the codecs plugin); any other
// image goes to cv::imread, except a JPEG whose header announces more pixels than its data can
// hold (damaged: cv::imread would allocate and fill them all, up to 1 Gpx).
#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace fv::io {

// An 8-bit BGR image; empty when `path` is missing or does not decode.
cv::Mat TryReadImage(const std::string& path);

// An 8-bit BGR image; throws fv::Error naming `path` when it is missing or does not decode.
cv::Mat ReadImage(const std::string& path);

// Writes beside `path` and renames over it when whole (a failed write leaves an earlier image);
// throws fv::Error naming `path` when the image cannot be written.
void WriteImage(const std::string& path, const cv::Mat& image);

}  // namespace fv::io
