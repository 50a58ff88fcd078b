#include "fieldvision/codecs/plugin.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio/registry.hpp>

namespace fv::codecs {
namespace {

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
};

}  // namespace
}  // namespace fv::codecs

extern "C" __attribute__((visibility("default"))) const fv::codecs::PluginApi*
fv_codecs_plugin_api() {
  return &fv::codecs::kApi;
}
