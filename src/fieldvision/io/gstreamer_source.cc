// Frame-source backend: GStreamer pipelines ("gst:PIPELINE", ending in an appsink or not) and
// RTSP URLs (IP cameras, phones) through OpenCV's GStreamer backend. Times are the stream's
// buffer timestamps anchored to the system clock at the first frame (TimeOrigin::kContainer),
// else the arrival time.
#include <cmath>

#include "fieldvision/codecs/codecs.h"
#include "fieldvision/io/live_source.h"
#include "fieldvision/io/source_backends.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::io::backend {
namespace {

class GStreamerSource : public LiveSource {
 public:
  GStreamerSource(const std::string& spec, const std::string& pipeline)
      : LiveSource(spec, "stream", true) {
    FV_REQUIRE(OpenCapture(*capture_, pipeline, cv::CAP_GSTREAMER),
               "stream '{}' cannot be opened (GStreamer: '{}')", spec, pipeline);
    fps_ = capture_->get(cv::CAP_PROP_FPS);
    if (!(std::isfinite(fps_) && fps_ > 0)) fps_ = 30.0;
    ReadFirstFrame();
  }

  std::string FramesNote() const override { return chroma_.Note(); }

 private:
  bool Grab(SourceFrame* out) override {
    double arrival_s = 0, ms = 0;  // ms: the buffer's PTS
    if (!ReadCapture(*capture_, &chroma_, out, &arrival_s, &ms)) return false;
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

  std::unique_ptr<cv::VideoCapture> capture_ = codecs::NewVideoCapture();
  RepeatedChromaRepair chroma_;
  double anchor_s_ = 0;  // system time of PTS 0
  double last_ms_ = -1;
};

}  // namespace

bool HaveGStreamer() { return codecs::HasVideoBackend(cv::CAP_GSTREAMER); }

std::unique_ptr<FrameSource> OpenGStreamer(const std::string& spec,
                                           const FrameSourceOptions& options) {
  FV_REQUIRE(HaveGStreamer(), "stream '{}': this OpenCV has no GStreamer backend", spec);
  std::string pipeline;
  if (util::StartsWith(spec, "gst:")) {
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

}  // namespace fv::io::backend
