// libFuzzer harness: JPEG stills (io/jpeg_orientation.h, io/jpeg_region.h). Whatever the bytes,
// the EXIF orientation is 1..8, the header gives a size or an fv::Error, and a decode gives an
// image of that size or an fv::Error.
#include <cstdio>
#include <cstdlib>

#include "fieldvision/io/jpeg_orientation.h"
#include "fieldvision/io/jpeg_region.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const int orientation = fv::io::JpegOrientation(data, size);
  if (orientation < 1 || orientation > 8) {
    std::fprintf(stderr, "fuzz: orientation %d\n", orientation);
    std::abort();
  }
  fv::fuzz::ExpectErrorOrValue([&] {
    const cv::Size header = fv::io::JpegRegionDecoder::ReadSize(data, size, "still.jpg");
    // Huge headers are valid JPEG but not worth decoding here.
    if (double(header.width) * header.height > double(1 << 22)) return;
    cv::Mat bgr;
    fv::io::JpegRegionDecoder decoder;
    decoder.Decode(data, size, cv::Rect(), &bgr, "still.jpg");
    if (bgr.size() != header || bgr.type() != CV_8UC3) {
      std::fprintf(stderr, "fuzz: decoded %dx%d, header %dx%d\n", bgr.cols, bgr.rows, header.width,
                   header.height);
      std::abort();
    }
  });
  return 0;
}
