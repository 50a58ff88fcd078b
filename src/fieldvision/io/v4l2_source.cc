// Frame-source backend: V4L2 cameras ("v4l2:/dev/videoN"; "camera:N" is /dev/videoN) through
// OpenCV's V4L2 backend. Times are the kernel's buffer timestamps (CLOCK_MONOTONIC at capture)
// moved to the system clock (TimeOrigin::kDevice), else the arrival time.
#include <cmath>
#include <filesystem>

#include "fieldvision/codecs/codecs.h"
#include "fieldvision/io/live_source.h"
#include "fieldvision/io/source_backends.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::io::backend {
namespace {

class V4l2Source : public LiveSource {
 public:
  V4l2Source(const std::string& spec, const std::string& device, const FrameSourceOptions& o)
      : LiveSource(spec, "camera", false) {
    FV_REQUIRE(std::filesystem::exists(device), "camera '{}': device '{}' does not exist", spec,
               device);
    FV_REQUIRE(OpenCapture(*capture_, device, cv::CAP_V4L2),
               "camera '{}': cannot open '{}' as a V4L2 camera", spec, device);
    if (o.width > 0) capture_->set(cv::CAP_PROP_FRAME_WIDTH, o.width);
    if (o.height > 0) capture_->set(cv::CAP_PROP_FRAME_HEIGHT, o.height);
    if (o.fps > 0) capture_->set(cv::CAP_PROP_FPS, o.fps);
    if (o.exposure_us > 0) {
      capture_->set(cv::CAP_PROP_AUTO_EXPOSURE, 1);                 // V4L2 manual mode
      capture_->set(cv::CAP_PROP_EXPOSURE, o.exposure_us / 100.0);  // units of 100 us
    }
    fps_ = capture_->get(cv::CAP_PROP_FPS);
    if (!(std::isfinite(fps_) && fps_ > 0)) fps_ = o.fps > 0 ? o.fps : 30.0;
    ReadFirstFrame();
  }

  std::string FramesNote() const override { return chroma_.Note(); }

 private:
  bool Grab(SourceFrame* out) override {
    // OpenCV's V4L2 backend reports the buffer's timestamp (ms on CLOCK_MONOTONIC).
    double arrival_s = 0, ms = 0;
    if (!ReadCapture(*capture_, &chroma_, out, &arrival_s, &ms)) return false;
    const double device_s = std::isfinite(ms) && ms > 0 ? SystemFromMonotonic(ms / 1000.0) : 0;
    if (device_s > 0 && std::abs(device_s - arrival_s) < 1.0) {
      out->time_s = device_s;
      out->origin = TimeOrigin::kDevice;
    } else {
      out->time_s = arrival_s;
      out->origin = TimeOrigin::kArrival;
    }
    return true;
  }

  std::unique_ptr<cv::VideoCapture> capture_ = codecs::NewVideoCapture();
  RepeatedChromaRepair chroma_;
};

}  // namespace

std::unique_ptr<FrameSource> OpenV4l2(const std::string& spec, const FrameSourceOptions& options) {
  std::string device;
  if (util::StartsWith(spec, "camera:")) {
    const long long n = util::ParseInt(spec.substr(7), "camera number in '" + spec + "'");
    FV_REQUIRE(n >= 0, "camera '{}': the number must be >= 0", spec);
    device = "/dev/video" + std::to_string(n);
  } else {
    device = spec.substr(5);
    FV_REQUIRE(!device.empty(), "camera '{}': give a device, e.g. v4l2:/dev/video0", spec);
  }
  return std::make_unique<V4l2Source>(spec, device, options);
}

}  // namespace fv::io::backend
