#include "fieldvision/codecs/codecs.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "fieldvision/codecs/plugin.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/program_paths.h"

namespace fv::codecs {
namespace {

constexpr const char* kPluginFile = "libfieldvision_codecs.so";

// Where the plugin may be: where the install rules put it (bin/../lib/fieldvision), beside the
// program as built (build/bin/../lib), then where this build wrote it (test programs live
// elsewhere in the build).
std::vector<std::filesystem::path> PluginCandidates() {
  std::vector<std::filesystem::path> out;
  const std::filesystem::path bin = util::ProgramDir();
  if (!bin.empty()) {
    out.push_back(util::InstalledPluginDir() / kPluginFile);
    out.push_back(bin.parent_path() / "lib" / kPluginFile);
  }
#ifdef FV_CODECS_PLUGIN
  const std::filesystem::path built(FV_CODECS_PLUGIN);
  std::error_code ec;
  bool listed = false;
  for (const auto& p : out) listed = listed || std::filesystem::weakly_canonical(p, ec) == built;
  if (!listed) out.push_back(built);
#endif
  return out;
}

// GLib's log (GStreamer's "GStreamer-CRITICAL **: ... Trying to dispose element pipeline0", 26
// lines when OpenCV's GStreamer capture fails on a damaged file) goes through GLib's default
// handler; once the plugin has brought GLib in, that is replaced, found at run time in the
// plugin's dependencies (no GLib header or link needed), by one that passes messages on only
// when SetLibraryLogs(true).
using GLogFunc = void (*)(const char* domain, int level, const char* message, void* data);
GLogFunc g_glib_default_log = nullptr;
std::atomic<bool> g_library_logs{false};

void GLibLog(const char* domain, int level, const char* message, void* data) {
  if (g_library_logs && g_glib_default_log != nullptr) {
    g_glib_default_log(domain, level, message, data);
  }
}

void QuietGLib(void* plugin) {
  using SetHandler = GLogFunc (*)(GLogFunc, void*);
  auto set = reinterpret_cast<SetHandler>(dlsym(plugin, "g_log_set_default_handler"));
  auto fallback = reinterpret_cast<GLogFunc>(dlsym(plugin, "g_log_default_handler"));
  if (set == nullptr) return;  // no GLib (OpenCV built without GStreamer)
  g_glib_default_log = fallback;
  set(&GLibLog, nullptr);
}

const PluginApi* LoadPlugin() {
  std::string tried;
  for (const auto& path : PluginCandidates()) {
    if (!std::filesystem::exists(path)) {
      tried += (tried.empty() ? "" : ", ") + path.string();
      continue;
    }
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    FV_REQUIRE(handle != nullptr, "cannot load the image and video codecs plugin '{}': {}",
               path.string(), dlerror());
    using Entry = const PluginApi* (*)();
    auto entry = reinterpret_cast<Entry>(dlsym(handle, "fv_codecs_plugin_api"));
    FV_REQUIRE(entry != nullptr, "codecs plugin '{}' has no fv_codecs_plugin_api", path.string());
    const PluginApi* api = entry();
    FV_REQUIRE(api != nullptr && api->version == kPluginApiVersion,
               "codecs plugin '{}' is from another build (interface version {}, expected {})",
               path.string(), api ? api->version : -1, kPluginApiVersion);
    QuietGLib(handle);
    spdlog::debug("codecs plugin: {}", path.string());
    return api;  // never unloaded: its objects (captures, writers) may outlive any owner here
  }
  Throw(
      "the image and video codecs plugin {} is missing (looked for {}; build the target "
      "fieldvision_codecs)",
      kPluginFile, tried);
}

std::atomic<const PluginApi*> g_loaded{nullptr};

const PluginApi& Api() {
  static const PluginApi* api = [] {
    const PluginApi* loaded = LoadPlugin();
    g_loaded = loaded;
    return loaded;
  }();
  return *api;
}

// Sends stderr to /dev/null while any decode runs: libpng's and libjpeg's default handlers,
// which OpenCV's decoders keep, print "libpng error: ..." or "Premature end of JPEG file" before
// imread returns; our one-line error says what went wrong. Counted, so that decodes on several
// threads share one redirection (the first in saves stderr, the last out restores it).
struct QuietState {
  std::mutex mutex;
  int depth = 0;   // decodes running
  int saved = -1;  // the real stderr while depth > 0
};
QuietState& Quiet() {
  static QuietState state;
  return state;
}

class QuietStderr {
 public:
  QuietStderr() {
    QuietState& q = Quiet();
    const std::lock_guard<std::mutex> lock(q.mutex);
    if (q.depth++ > 0) return;
    std::fflush(stderr);
    q.saved = ::dup(STDERR_FILENO);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (q.saved >= 0 && null >= 0) ::dup2(null, STDERR_FILENO);
    if (null >= 0) ::close(null);
  }
  ~QuietStderr() {
    QuietState& q = Quiet();
    const std::lock_guard<std::mutex> lock(q.mutex);
    if (--q.depth > 0 || q.saved < 0) return;
    std::fflush(stderr);
    ::dup2(q.saved, STDERR_FILENO);
    ::close(q.saved);
    q.saved = -1;
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;
};

}  // namespace

void Load() { Api(); }

void SetLibraryLogs(bool shown) { g_library_logs = shown; }

long long DecoderProblems() {
  const PluginApi* api = g_loaded;
  return api != nullptr ? api->decoder_problems() : 0;
}

cv::Mat ImRead(const std::string& path, int flags) {
  const PluginApi& api = Api();
  const QuietStderr quiet;
  return api.imread(path, flags);
}

bool ImWrite(const std::string& path, cv::InputArray image, const std::vector<int>& params) {
  return Api().imwrite(path, image, params);
}

cv::Mat ImDecode(cv::InputArray buffer, int flags) {
  const PluginApi& api = Api();
  const QuietStderr quiet;
  return api.imdecode(buffer, flags);
}

bool ImEncode(const std::string& ext, cv::InputArray image, std::vector<uchar>* buffer,
              const std::vector<int>& params) {
  return Api().imencode(ext, image, *buffer, params);
}

std::unique_ptr<cv::VideoCapture> NewVideoCapture() {
  return std::unique_ptr<cv::VideoCapture>(Api().new_capture());
}

std::unique_ptr<cv::VideoWriter> NewVideoWriter() {
  return std::unique_ptr<cv::VideoWriter>(Api().new_writer());
}

bool OpenVideoWriter(cv::VideoWriter* writer, const std::string& path, int api, int fourcc,
                     double fps, cv::Size size, bool is_color) {
  return Api().open_writer(*writer, path, api, fourcc, fps, size, is_color);
}

std::string BackendName(const cv::VideoCapture& capture) { return Api().backend_name(capture); }

bool HasVideoBackend(int api) { return Api().has_backend(api); }

}  // namespace fv::codecs
