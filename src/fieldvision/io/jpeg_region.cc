#include "fieldvision/io/jpeg_region.h"

#include <algorithm>
#include <csetjmp>
#include <cstdio>

#include <jpeglib.h>

#include "fieldvision/util/error.h"

namespace fv::io {
namespace {

// libjpeg reports fatal errors through error_exit, which must not return: jump back to the
// caller with the message. Only plain C data lives between setjmp and longjmp.
struct ErrorManager {
  jpeg_error_mgr pub;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
  long warnings;
};

void OnError(j_common_ptr cinfo) {
  auto* err = reinterpret_cast<ErrorManager*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, err->message);
  std::longjmp(err->jump, 1);
}

void OnMessage(j_common_ptr cinfo, int level) {
  if (level < 0) ++reinterpret_cast<ErrorManager*>(cinfo->err)->warnings;  // not printed
}

struct Job {
  const uint8_t* data;
  size_t size;
  bool header_only;
  int x, y, w, h;  // requested region; w <= 0: all
  cv::Mat* bgr;
  // Results.
  int width, height;
  int out_x, out_y, out_w, out_h;
};

// Returns false with err->message set on a libjpeg error.
bool RunJob(Job* job, ErrorManager* err) {
  jpeg_decompress_struct cinfo;
  cinfo.err = jpeg_std_error(&err->pub);
  err->pub.error_exit = OnError;
  err->pub.emit_message = OnMessage;
  err->message[0] = '\0';
  err->warnings = 0;
  if (setjmp(err->jump)) {
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, job->data, static_cast<unsigned long>(job->size));
  jpeg_read_header(&cinfo, TRUE);
  job->width = static_cast<int>(cinfo.image_width);
  job->height = static_cast<int>(cinfo.image_height);
  if (job->header_only) {
    jpeg_destroy_decompress(&cinfo);
    return true;
  }
  cinfo.out_color_space = JCS_EXT_BGR;
  jpeg_start_decompress(&cinfo);
  cv::Mat& bgr = *job->bgr;
  int x0 = 0, y0 = 0, y1 = job->height;
  JDIMENSION xoff = 0, width = cinfo.output_width;
  if (job->w > 0) {
    xoff = static_cast<JDIMENSION>(job->x);
    width = static_cast<JDIMENSION>(job->w);
    if (xoff != 0 || width != cinfo.output_width) jpeg_crop_scanline(&cinfo, &xoff, &width);
    x0 = static_cast<int>(xoff);
    y0 = job->y;
    y1 = job->y + job->h;
    if (y0 > 0) jpeg_skip_scanlines(&cinfo, static_cast<JDIMENSION>(y0));
    y0 = static_cast<int>(cinfo.output_scanline);
  }
  while (static_cast<int>(cinfo.output_scanline) < y1) {
    JSAMPROW row =
        bgr.ptr<uint8_t>(static_cast<int>(cinfo.output_scanline)) + 3 * static_cast<ptrdiff_t>(x0);
    if (jpeg_read_scanlines(&cinfo, &row, 1) != 1) break;
  }
  job->out_x = x0;
  job->out_y = y0;
  job->out_w = static_cast<int>(width);
  job->out_h = static_cast<int>(cinfo.output_scanline) - y0;
  // The rows below are not needed: abort instead of decoding them.
  jpeg_abort_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return true;
}

// Twice the bound of entropy coding (JpegRegionDecoder::Decode).
constexpr double kMaxPixelsPerByte = 1024.0;
constexpr int kMinCropWidth = 16;

}  // namespace

cv::Size JpegRegionDecoder::ReadSize(const uint8_t* data, size_t size, const std::string& what) {
  FV_REQUIRE(data != nullptr && size > 2 && data[0] == 0xFF && data[1] == 0xD8, "{}: not JPEG data",
             what);
  Job job{data, size, true, 0, 0, 0, 0, nullptr, 0, 0, 0, 0, 0, 0};
  ErrorManager err;
  FV_REQUIRE(RunJob(&job, &err), "{}: cannot read the JPEG header ({})", what, err.message);
  return {job.width, job.height};
}

bool JpegRegionDecoder::CanHold(size_t size, const cv::Size& image) {
  return double(image.width) * image.height <= kMaxPixelsPerByte * double(size);
}

cv::Rect JpegRegionDecoder::Decode(const uint8_t* data, size_t size, const cv::Rect& region,
                                   cv::Mat* bgr, const std::string& what) {
  FV_REQUIRE(bgr != nullptr, "JpegRegionDecoder::Decode: no output image");
  const cv::Size image = ReadSize(data, size, what);
  // Decoding a header that announces far more than the data holds would fill gigabytes with
  // nothing (found by fuzz/jpeg_still_fuzz.cc).
  FV_REQUIRE(CanHold(size, image),
             "{}: the header announces {}x{} pixels, more than {} bytes of JPEG data can hold "
             "(damaged)",
             what, image.width, image.height, size);
  if (bgr->size() != image || bgr->type() != CV_8UC3) bgr->create(image, CV_8UC3);
  const cv::Rect r = region.empty() ? cv::Rect() : region & cv::Rect(cv::Point(0, 0), image);
  FV_REQUIRE(region.empty() || !r.empty(), "{}: region {}x{}+{}+{} is outside the {}x{} image",
             what, region.width, region.height, region.x, region.y, image.width, image.height);
  // A cropped decode's first and last columns lack the chroma neighbours that fancy upsampling
  // uses: decode one column more on each side and leave those out of the exact rectangle.
  // A crop only a few columns wide gets libjpeg-turbo's upsampling wrong even inside it (at the
  // image's left edge, 55 levels off in one column): at least kMinCropWidth columns are decoded.
  const int x0 = r.empty() ? 0 : std::max(r.x - 1, 0);
  const int x1 =
      r.empty() ? 0 : std::min(std::max(r.x + r.width + 1, x0 + kMinCropWidth), image.width);
  Job job{data, size, false, x0, r.y, x1 - x0, r.height, bgr, 0, 0, 0, 0, 0, 0};
  ErrorManager err;
  const bool ok = RunJob(&job, &err);
  warnings_ += err.warnings;
  FV_REQUIRE(ok, "{}: corrupt JPEG data ({})", what, err.message);
  int left = job.out_x, right = job.out_x + job.out_w;
  if (left > 0) ++left;
  if (right < image.width) --right;
  return {left, job.out_y, right - left, job.out_h};
}

}  // namespace fv::io
