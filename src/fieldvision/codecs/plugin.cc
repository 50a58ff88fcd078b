#include "fieldvision/codecs/plugin.h"

#include <atomic>
#include <cstring>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio/registry.hpp>

#ifdef FV_HAVE_AVUTIL
extern "C" {
#include <libavutil/log.h>
}
#endif

namespace fv::codecs {
namespace {

#ifdef FV_HAVE_AVUTIL
std::atomic<long long> g_decoder_problems{0};

// FFmpeg's log: a decoder's error, or its concealment of damaged data ("concealing 52 DC, 52 AC,
// 52 MV errors in P frame", logged as information), is counted; the rest goes on as FFmpeg's own
// callback would print it at the level set (OpenCV quiets it unless --verbose).
void CountingLog(void* avcl, int level, const char* fmt, va_list args) {
  const AVClass* cls = avcl != nullptr ? *static_cast<AVClass**>(avcl) : nullptr;
  const bool decoder = cls != nullptr && cls->category == AV_CLASS_CATEGORY_DECODER;
  if (fmt != nullptr &&
      (std::strstr(fmt, "concealing") != nullptr || (decoder && level <= AV_LOG_ERROR))) {
    ++g_decoder_problems;
  }
  if (level <= av_log_get_level()) av_log_default_callback(avcl, level, fmt, args);
}

long long DecoderProblems() {
  av_log_set_callback(&CountingLog);
  return g_decoder_problems.load();
}
#else
long long DecoderProblems() { return -1; }
#endif

const PluginApi kApi{
    kPluginApiVersion,
    [](const std::string& path, int flags) { return cv::imread(path, flags); },
    [](const std::string& path, cv::InputArray image, const std::vector<int>& params) {
      return cv::imwrite(path, image, params);
    },
    [](cv::InputArray buffer, int flags) { return cv::imdecode(buffer, flags); },
    [](const std::string& ext, cv::InputArray image, std::vector<uchar>& buffer,
       const std::vector<int>& params) { return cv::imencode(ext, image, buffer, params); },
    []() { return new cv::VideoCapture(); },
    []() { return new cv::VideoWriter(); },
    [](cv::VideoWriter& writer, const std::string& path, int api, int fourcc, double fps,
       cv::Size size,
       bool is_color) { return writer.open(path, api, fourcc, fps, size, is_color); },
    [](const cv::VideoCapture& capture) {
      return capture.isOpened() ? capture.getBackendName() : std::string();
    },
    [](int api) {
      return cv::videoio_registry::hasBackend(static_cast<cv::VideoCaptureAPIs>(api));
    },
    &DecoderProblems,
};

}  // namespace
}  // namespace fv::codecs

extern "C" __attribute__((visibility("default"))) const fv::codecs::PluginApi*
fv_codecs_plugin_api() {
  return &fv::codecs::kApi;
}
