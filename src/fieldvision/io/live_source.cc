#include "fieldvision/io/live_source.h"

#include <filesystem>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"

namespace fv::io::backend {

LiveSource::LiveSource(std::string spec, std::string noun, bool may_end)
    : spec_(std::move(spec)), noun_(std::move(noun)), may_end_(may_end) {}

void LiveSource::ReadFirstFrame() {
  FV_REQUIRE(Grab(&pending_), "{} '{}' delivers no frame", noun_, spec_);
  size_ = pending_.bgr.size();
  has_pending_ = true;
}

bool LiveSource::ReadFrame(SourceFrame* out) {
  if (has_pending_) {
    std::swap(*out, pending_);
    has_pending_ = false;
  } else if (!Grab(out)) {
    if (may_end_) return false;  // end of stream
    Throw("{} '{}' stopped delivering frames (disconnected?)", noun_, spec_);
  }
  out->frame = next_++;
  return true;
}

bool OpenCapture(cv::VideoCapture& capture, const std::string& target, int api) {
  try {
    return capture.open(target, api) && capture.isOpened();
  } catch (const cv::Exception&) {
    return false;
  }
}

bool ReadCapture(cv::VideoCapture& capture, RepeatedChromaRepair* chroma, SourceFrame* out,
                 double* arrival_s, double* pos_ms) {
  bool ok = false;
  try {
    ok = capture.read(out->bgr);
  } catch (const cv::Exception&) {
    ok = false;
  }
  *arrival_s = SystemClockNow();
  if (!ok || out->bgr.empty()) return false;
  if (out->bgr.channels() == 1) cv::cvtColor(out->bgr, out->bgr, cv::COLOR_GRAY2BGR);
  chroma->Apply(&out->bgr);
  out->jpeg.clear();
  *pos_ms = capture.get(cv::CAP_PROP_POS_MSEC);
  return true;
}

bool OpenVideoFile(cv::VideoCapture& capture, const std::string& path) {
  // A file that exists is a video even when its name has a '%' (100%.avi).
  const int api = path.find('%') != std::string::npos && !std::filesystem::is_regular_file(path)
                      ? cv::CAP_IMAGES
                      : cv::CAP_FFMPEG;
  return OpenCapture(capture, path, api);
}

}  // namespace fv::io::backend
