// Frame-source backend: GStreamer pipelines ("gst:PIPELINE", ending in an appsink or not) and
// RTSP URLs (IP cameras, phones) through OpenCV's GStreamer backend. Times are the stream's
// buffer timestamps anchored to the system clock at the first frame (TimeOrigin::kContainer),
// else the arrival time.
#include <cmath>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "fieldvision/io/source_backends.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::io_backend {
namespace {

class GStreamerSource : public FrameSource {
 public:
  GStreamerSource(const std::string& spec, const std::string& pipeline) : spec_(spec) {
    bool opened = false;
    try {
      opened = capture_.open(pipeline, cv::CAP_GSTREAMER);
    } catch (const cv::Exception&) {
      opened = false;
    }
    FV_REQUIRE(opened && capture_.isOpened(), "stream '{}' cannot be opened (GStreamer: '{}')",
               spec, pipeline);
    fps_ = capture_.get(cv::CAP_PROP_FPS);
    if (!(std::isfinite(fps_) && fps_ > 0)) fps_ = 30.0;
    FV_REQUIRE(Grab(&pending_), "stream '{}' delivers no frame", spec);
    size_ = pending_.bgr.size();
    has_pending_ = true;
  }

  bool ReadFrame(SourceFrame* out) override {
    if (has_pending_) {
      std::swap(*out, pending_);
      has_pending_ = false;
    } else if (!Grab(out)) {
      return false;  // end of stream
    }
    out->frame = next_++;
    return true;
  }
  cv::Size FrameSize() const override { return size_; }
  std::string name() const override { return spec_; }
  double fps() const override { return fps_; }
  bool live() const override { return true; }

 private:
  bool Grab(SourceFrame* out) {
    bool ok = false;
    try {
      ok = capture_.read(out->bgr);
    } catch (const cv::Exception&) {
      ok = false;
    }
    const double arrival_s = SystemClockNow();
    if (!ok || out->bgr.empty()) return false;
    if (out->bgr.channels() == 1) cv::cvtColor(out->bgr, out->bgr, cv::COLOR_GRAY2BGR);
    out->jpeg.clear();
    const double ms = capture_.get(cv::CAP_PROP_POS_MSEC);  // the buffer's PTS
    if (std::isfinite(ms) && ms >= 0 && (anchor_s_ == 0 || ms > last_ms_)) {
      if (anchor_s_ == 0) anchor_s_ = arrival_s - ms / 1000.0;
      last_ms_ = ms;
      out->time_s = anchor_s_ + ms / 1000.0;
      out->origin = TimeOrigin::kContainer;
    } else {
      out->time_s = arrival_s;
      out->origin = TimeOrigin::kArrival;
    }
    return true;
  }

  std::string spec_;
  cv::VideoCapture capture_;
  SourceFrame pending_;
  bool has_pending_ = false;
  long long next_ = 0;
  double fps_ = 30.0;
  double anchor_s_ = 0;  // system time of PTS 0
  double last_ms_ = -1;
  cv::Size size_;
};

}  // namespace

bool HaveGStreamer() { return cv::videoio_registry::hasBackend(cv::CAP_GSTREAMER); }

std::unique_ptr<FrameSource> OpenGStreamer(const std::string& spec,
                                           const FrameSourceOptions& options) {
  FV_REQUIRE(HaveGStreamer(), "stream '{}': this OpenCV has no GStreamer backend", spec);
  std::string pipeline;
  if (StartsWith(spec, "gst:")) {
    pipeline = spec.substr(4);
    FV_REQUIRE(!pipeline.empty(), "stream '{}': give a pipeline after 'gst:'", spec);
    if (pipeline.find("appsink") == std::string::npos) {
      pipeline += " ! videoconvert ! video/x-raw,format=BGR ! appsink drop=true max-buffers=" +
                  std::to_string(options.live_buffer_frames);
    }
  } else {
    pipeline = "rtspsrc location=" + spec +
               " latency=0 ! decodebin ! videoconvert ! video/x-raw,format=BGR ! appsink "
               "drop=true sync=false max-buffers=" +
               std::to_string(options.live_buffer_frames);
  }
  return std::make_unique<GStreamerSource>(spec, pipeline);
}

}  // namespace fv::io_backend
