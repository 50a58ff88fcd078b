// Frame-source backend: a finite source (a file, a rendered scene) delivered as a live camera
// would deliver it. Frame k is captured at start + k / fps on the system clock (start: the given
// Unix time, else the first read) and stamped so
// (TimeOrigin::kPlayback); a reader that asks early waits for it, a reader more than
// live_buffer_frames behind finds the oldest frames gone (skipped and counted), as with a
// camera's driver buffers.
#include <chrono>
#include <cmath>
#include <thread>

#include "fieldvision/io/source_backends.h"
#include "fieldvision/util/error.h"

namespace fv::io::backend {
namespace {

class PacedSource : public FrameSource {
 public:
  PacedSource(std::unique_ptr<FrameSource> source, const FrameSourceOptions& options)
      : source_(std::move(source)),
        start_s_(options.start_at_s),
        buffer_(options.live_buffer_frames) {
    FV_REQUIRE(source_->fps() > 0, "video '{}': no frame rate to play it at", source_->name());
  }

  bool ReadFrame(SourceFrame* out) override {
    if (start_s_ <= 0) start_s_ = SystemClockNow();  // no start given: the first read starts it
    const double period_s = 1.0 / source_->fps();
    // The newest frame captured by now; older than newest - buffer + 1 is gone.
    const double now = SystemClockNow();
    const long long newest = static_cast<long long>(std::floor((now - start_s_) / period_s));
    while (next_ < newest - buffer_ + 1) {
      if (!source_->SkipFrame()) return false;
      ++next_;
      ++dropped_;
    }
    if (!source_->ReadFrame(out)) return false;
    const double capture_s = start_s_ + next_ * period_s;
    const double wait_s = capture_s - SystemClockNow();
    if (wait_s > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
    out->frame = next_++;
    out->time_s = capture_s;
    out->origin = TimeOrigin::kPlayback;
    return true;
  }
  long long FrameCount() const override { return source_->FrameCount(); }
  cv::Size FrameSize() const override { return source_->FrameSize(); }
  std::string name() const override { return source_->name(); }
  double fps() const override { return source_->fps(); }
  bool rate_known() const override { return source_->rate_known(); }
  bool SkipsWithoutDecoding() const override { return source_->SkipsWithoutDecoding(); }
  bool live() const override { return true; }
  bool encoded() const override { return source_->encoded(); }
  long long dropped() const override { return dropped_; }

 private:
  std::unique_ptr<FrameSource> source_;
  double start_s_;
  int buffer_;
  long long next_ = 0;
  long long dropped_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> Paced(std::unique_ptr<FrameSource> source,
                                   const FrameSourceOptions& options) {
  return std::make_unique<PacedSource>(std::move(source), options);
}

}  // namespace fv::io::backend
