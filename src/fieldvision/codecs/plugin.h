// The table of functions the codecs plugin (plugin.cc, built as libfieldvision_codecs.so and
// linked to OpenCV's imgcodecs and videoio) exports to codecs.cc, which loads it with dlopen().
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

namespace fv::codecs {

inline constexpr int kPluginApiVersion = 2;

struct PluginApi {
  int version = kPluginApiVersion;
  cv::Mat (*imread)(const std::string& path, int flags);
  bool (*imwrite)(const std::string& path, cv::InputArray image, const std::vector<int>& params);
  cv::Mat (*imdecode)(cv::InputArray buffer, int flags);
  bool (*imencode)(const std::string& ext, cv::InputArray image, std::vector<uchar>& buffer,
                   const std::vector<int>& params);
  cv::VideoCapture* (*new_capture)();
  cv::VideoWriter* (*new_writer)();
  bool (*open_writer)(cv::VideoWriter& writer, const std::string& path, int api, int fourcc,
                      double fps, cv::Size size, bool is_color);
  std::string (*backend_name)(const cv::VideoCapture& capture);
  bool (*has_backend)(int api);
  // Damaged data FFmpeg's decoders reported (concealed errors) since the first call, which (and
  // each later one) routes FFmpeg's log through the plugin's counter: call it after a capture
  // opened (OpenCV sets its own log callback at its first open). -1: counting not built in.
  long long (*decoder_problems)();
};

}  // namespace fv::codecs

// The plugin's one exported symbol.
extern "C" const fv::codecs::PluginApi* fv_codecs_plugin_api();
