// Decoding of JPEG frames (MJPG video packets, JPEG images) in full or only a region, with
// libjpeg-turbo: rows below the region are never entropy-decoded and columns outside it skip the
// inverse DCT and colour conversion (jpeg_skip_scanlines, jpeg_crop_scanline), so looking at a
// tracked ball costs a fraction of a full decode. Written here because cv::imdecode and
// cv::VideoCapture only decode whole frames.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

namespace fv::io {

class JpegRegionDecoder {
 public:
  // The image size from the JPEG header; throws fv::Error naming `what` when the data is not a
  // JPEG image.
  static cv::Size ReadSize(const uint8_t* data, size_t size, const std::string& what);
  // Whether `size` bytes of JPEG data can hold an image of `image` pixels: entropy coding spends
  // at least a bit on each 8x8 block of each component, so real data holds at most 512 pixels a
  // byte; the bound is 1024. A header announcing more is damaged.
  static bool CanHold(size_t size, const cv::Size& image);

  // Decodes `region` of the JPEG (clipped to the image and widened to whole blocks; empty: the
  // whole image) into `bgr`, which is (re)allocated to the image size when it is not already.
  // Returns the rectangle decoded exactly (as a whole-image decode would); besides it only the
  // column just left and right of it may change. Throws fv::Error naming `what` for data
  // libjpeg cannot decode or whose header announces more pixels than the data can hold (over
  // 1024 a byte); recoverable damage (data that ends early) is decoded as far as it goes and
  // counted in warnings().
  cv::Rect Decode(const uint8_t* data, size_t size, const cv::Rect& region, cv::Mat* bgr,
                  const std::string& what);

  // libjpeg warnings so far (e.g. "premature end of data segment").
  long long warnings() const { return warnings_; }

 private:
  long long warnings_ = 0;
};

}  // namespace fv::io
