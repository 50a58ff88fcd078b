#include "fieldvision/detect/camera_background.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include <fmt/format.h>

#include "fieldvision/util/error.h"

namespace fv::detect {

void CameraBackgroundOptions::Check() const {
  background.Check();
  CheckPositive(window_s, "window_s");
  CheckNonNegative(decoded_window_s, "decoded_window_s");
}

std::vector<cv::Mat> SampleFrames(io::FrameSource* source, int samples, double window_s,
                                  int scale) {
  std::vector<cv::Mat> out;
  const long long count = source->FrameCount();
  if (count <= 0 || samples <= 0) return out;
  const double fps = source->fps() > 0 ? source->fps() : 30.0;
  const long long span = std::min(count, std::max(1LL, std::llround(window_s * fps)));
  const int n = static_cast<int>(std::min<long long>(samples, span));
  cv::Mat bgr;  // decoded into the same buffer each time (fresh pages cost more than decoding)
  long long next = 0;  // the source's next frame
  for (int k = 0; k < n; ++k) {
    // Sample k is frame round(k (span - 1) / (n - 1)).
    const long long frame =
        n > 1 ? std::llround(static_cast<double>(k) * static_cast<double>(span - 1) / (n - 1)) : 0;
    // Frame by frame: Motion-JPEG packets and image files skip without decoding, H.264 and the
    // like decode each frame without converting it (a seek would decode from the key frame
    // before each sample).
    bool reached = true;
    for (; reached && next < frame; ++next) reached = source->SkipFrame();
    if (!reached) break;
    long long read = 0;
    double t = 0.0;
    try {
      ++next;
      if (!source->Read(&bgr, &read, &t)) break;
      out.push_back(Background::Reduce(bgr, scale));
    } catch (const Error&) {
      // A damaged frame: the others still make a background.
    }
  }
  return out;
}

CameraBackground::CameraBackground(std::string spec, const CameraBackgroundOptions& options)
    : spec_(std::move(spec)), options_(options) {
  options_.Check();
}

void CameraBackground::Start() {
  if (!started_.valid()) started_ = std::async(std::launch::async, [this] { Build(); });
}

const Background* CameraBackground::Get() {
  Build();
  std::lock_guard<std::mutex> lock(mutex_);
  used_ = true;
  return background_ && background_->usable() ? &*background_ : nullptr;
}

void CameraBackground::Build() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!tried_) {
    tried_ = true;
    try {
      io::FrameSourceOptions so;
      so.encoded = true;  // skipped frames are not decoded
      auto source = io::OpenFrameSource(spec_, so);
      if (source->FrameCount() <= 0) {
        why_none_ = "a live source: no frames to sample ahead";
        return;
      }
      double window_s = options_.window_s;
      if (!source->SkipsWithoutDecoding()) {
        if (options_.decoded_window_s <= 0) {
          why_none_ = "its frames are not Motion-JPEG or image files (sampling would decode them)";
          return;
        }
        window_s = std::min(window_s, options_.decoded_window_s);
        decoded_ = true;
      }
      std::vector<cv::Mat> sampled = SampleFrames(source.get(), options_.background.samples,
                                                  window_s, options_.background.scale);
      sampled_ = static_cast<int>(sampled.size());
      if (sampled_ < 3) {
        why_none_ = fmt::format("{} frames to sample", sampled_);
      } else {
        background_.emplace(std::move(sampled), source->FrameSize(), options_.background);
        if (!background_->usable()) why_none_ = background_->Summary();
      }
    } catch (const std::exception& e) {  // fv::Error, or OpenCV's from a damaged frame
      why_none_ = e.what();
    }
  }
}

BackgroundFn CameraBackground::FnFor(std::shared_ptr<CameraBackground> self) {
  return [self = std::move(self)]() { return self->Get(); };
}

std::string CameraBackground::Summary() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!used_) return kNotNeeded;
  if (background_ && background_->usable()) {
    return fmt::format("{} from {} frames{}", background_->Summary(), sampled_,
                       decoded_ ? " (read in order, each decoded)" : "");
  }
  return "no background: " + why_none_;
}

}  // namespace fv::detect
