// Frame-source backend: GigE Vision and USB3 Vision cameras through Aravis ("aravis:" for the
// first camera found, "aravis:DEVICE-ID" for one, as `arv-tool-0.8` lists them; "aravis:Fake_1"
// is Aravis' simulated camera). Exposure and the trigger source (FrameSourceOptions) are passed
// to the camera. Times are the camera's timestamps anchored to the system clock at the first
// frame (TimeOrigin::kDevice), else the host's time of arrival. Compiled only when
// libaravis-dev was found (FV_HAVE_ARAVIS).
#include "fieldvision/io/live_source.h"
#include "fieldvision/io/source_backends.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

#ifdef FV_HAVE_ARAVIS
#include <arv.h>

#include <opencv2/imgproc.hpp>
#endif

namespace fv::io::backend {

#ifndef FV_HAVE_ARAVIS

bool HaveAravis() { return false; }

std::unique_ptr<FrameSource> OpenAravis(const std::string& spec, const FrameSourceOptions&) {
  Throw(
      "camera '{}': this fieldvision was built without Aravis (install libaravis-dev and "
      "rebuild)",
      spec);
}

#else

namespace {

// Throws fv::Error naming `spec` and `what` when `error` is set.
void Check(GError* error, const std::string& spec, const char* what) {
  if (error == nullptr) return;
  const std::string message = error->message;
  g_error_free(error);
  Throw("camera '{}': {} failed: {}", spec, what, message);
}

class AravisSource : public LiveSource {
 public:
  AravisSource(const std::string& spec, const std::string& id, const FrameSourceOptions& o)
      : LiveSource(spec, "camera", false) {
    if (util::StartsWith(id, "Fake")) arv_enable_interface("Fake");
    GError* error = nullptr;
    camera_ = arv_camera_new(id.empty() ? nullptr : id.c_str(), &error);
    Check(error, spec, "opening the camera");
    FV_REQUIRE(camera_ != nullptr, "camera '{}': no Aravis camera found", spec);
    if (o.width > 0 && o.height > 0) {
      arv_camera_set_region(camera_, 0, 0, o.width, o.height, &error);
      Check(error, spec, "setting the image size");
    }
    if (o.fps > 0) {
      arv_camera_set_frame_rate(camera_, o.fps, &error);
      Check(error, spec, "setting the frame rate");
    }
    if (o.exposure_us > 0) {
      arv_camera_set_exposure_time_auto(camera_, ARV_AUTO_OFF, &error);
      if (error != nullptr) g_clear_error(&error);  // some cameras have no auto exposure
      arv_camera_set_exposure_time(camera_, o.exposure_us, &error);
      Check(error, spec, "setting the exposure");
    }
    if (!o.trigger.empty()) {
      arv_camera_set_trigger(camera_, o.trigger.c_str(), &error);
      Check(error, spec, "setting the trigger");
    }
    fps_ = arv_camera_get_frame_rate(camera_, &error);
    if (error != nullptr || !(fps_ > 0)) {
      g_clear_error(&error);
      fps_ = o.fps > 0 ? o.fps : 30.0;
    }
    const guint payload = arv_camera_get_payload(camera_, &error);
    Check(error, spec, "reading the payload size");
    stream_ = arv_camera_create_stream(camera_, nullptr, nullptr, &error);
    Check(error, spec, "creating the stream");
    for (int i = 0; i < std::max(2, o.live_buffer_frames); ++i) {
      arv_stream_push_buffer(stream_, arv_buffer_new(payload, nullptr));
    }
    arv_camera_start_acquisition(camera_, &error);
    Check(error, spec, "starting the acquisition");
    ReadFirstFrame();
  }

  ~AravisSource() override {
    if (camera_ != nullptr) arv_camera_stop_acquisition(camera_, nullptr);
    if (stream_ != nullptr) g_object_unref(stream_);
    if (camera_ != nullptr) g_object_unref(camera_);
  }

  long long dropped() const override { return dropped_; }

 private:
  // The next complete buffer as BGR (incomplete buffers are counted as dropped).
  bool Grab(SourceFrame* out) override {
    for (int tries = 0; tries < 100; ++tries) {
      ArvBuffer* buffer = arv_stream_timeout_pop_buffer(stream_, 2000000);  // 2 s
      if (buffer == nullptr) return false;
      if (arv_buffer_get_status(buffer) != ARV_BUFFER_STATUS_SUCCESS) {
        ++dropped_;
        arv_stream_push_buffer(stream_, buffer);
        continue;
      }
      size_t bytes = 0;
      const void* data = arv_buffer_get_image_data(buffer, &bytes);
      const int w = arv_buffer_get_image_width(buffer);
      const int h = arv_buffer_get_image_height(buffer);
      const ArvPixelFormat format = arv_buffer_get_image_pixel_format(buffer);
      ToBgr(data, bytes, w, h, format, &out->bgr);
      const double device_s = 1e-9 * static_cast<double>(arv_buffer_get_timestamp(buffer));
      const double system_s = 1e-9 * static_cast<double>(arv_buffer_get_system_timestamp(buffer));
      const double arrival_s = system_s > 0 ? system_s : SystemClockNow();
      arv_stream_push_buffer(stream_, buffer);
      out->jpeg.clear();
      if (device_s > 0) {
        if (anchor_s_ == 0) anchor_s_ = arrival_s - device_s;
        out->time_s = anchor_s_ + device_s;
        out->origin = TimeOrigin::kDevice;
      } else {
        out->time_s = arrival_s;
        out->origin = TimeOrigin::kArrival;
      }
      return true;
    }
    return false;
  }

  void ToBgr(const void* data, size_t bytes, int w, int h, ArvPixelFormat format, cv::Mat* bgr) {
    auto* p = const_cast<void*>(data);
    const auto need = [&](size_t channels) {
      FV_REQUIRE(bytes >= static_cast<size_t>(w) * h * channels,
                 "camera '{}': buffer of {} bytes for a {}x{} image", spec(), bytes, w, h);
    };
    switch (format) {
      case ARV_PIXEL_FORMAT_MONO_8:
        need(1);
        cv::cvtColor(cv::Mat(h, w, CV_8UC1, p), *bgr, cv::COLOR_GRAY2BGR);
        return;
      case ARV_PIXEL_FORMAT_BAYER_RG_8:  // GenICam names the first row, OpenCV the second
        need(1);
        cv::cvtColor(cv::Mat(h, w, CV_8UC1, p), *bgr, cv::COLOR_BayerBG2BGR);
        return;
      case ARV_PIXEL_FORMAT_BAYER_GR_8:
        need(1);
        cv::cvtColor(cv::Mat(h, w, CV_8UC1, p), *bgr, cv::COLOR_BayerGB2BGR);
        return;
      case ARV_PIXEL_FORMAT_BAYER_GB_8:
        need(1);
        cv::cvtColor(cv::Mat(h, w, CV_8UC1, p), *bgr, cv::COLOR_BayerGR2BGR);
        return;
      case ARV_PIXEL_FORMAT_BAYER_BG_8:
        need(1);
        cv::cvtColor(cv::Mat(h, w, CV_8UC1, p), *bgr, cv::COLOR_BayerRG2BGR);
        return;
      case ARV_PIXEL_FORMAT_RGB_8_PACKED:
        need(3);
        cv::cvtColor(cv::Mat(h, w, CV_8UC3, p), *bgr, cv::COLOR_RGB2BGR);
        return;
      case ARV_PIXEL_FORMAT_BGR_8_PACKED:
        need(3);
        cv::Mat(h, w, CV_8UC3, p).copyTo(*bgr);
        return;
      default:
        Throw(
            "camera '{}': pixel format 0x{:08x} is not supported (use Mono8, Bayer*8, RGB8 or "
            "BGR8)",
            spec(), static_cast<unsigned>(format));
    }
  }

  ArvCamera* camera_ = nullptr;
  ArvStream* stream_ = nullptr;
  long long dropped_ = 0;
  double anchor_s_ = 0;
};

}  // namespace

bool HaveAravis() { return true; }

std::unique_ptr<FrameSource> OpenAravis(const std::string& spec,
                                        const FrameSourceOptions& options) {
  return std::make_unique<AravisSource>(spec, spec.substr(7), options);
}

#endif

}  // namespace fv::io::backend
