// The EXIF orientation of a JPEG file's bytes (tag 0x0112 of IFD0 in its APP1 "Exif" segment,
// EXIF 2.3 / TIFF 6.0): 1 (as stored) to 8; 1 when the file has none or it does not parse.
// cv::imread turns a still by it, so a decoder that does not (io::JpegRegionDecoder) is used
// only for images whose orientation is 1. Written here because OpenCV keeps its EXIF reader
// internal.
#pragma once

#include <cstddef>
#include <cstdint>

namespace fv::io {

int JpegOrientation(const uint8_t* data, size_t size);

}  // namespace fv::io
