// Frame-source backend: a synthetic scene played live, "synth:PRESET_OR_SCENE.json?camera=NAME
// &seed=N&width=W&height=H&frames=N" (the parameters of `fieldvision synth`; camera: a name or an
// index, default the first). Frames are rendered on demand (synth/synth.h), JPEG-compressed at
// the scene's quality when encoded frames are asked for, and delivered at the scene's frame rate
// as a camera would, so camera nodes can be tested without cameras.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <thread>

#include <fmt/format.h>

#include "fieldvision/codecs/codecs.h"
#include "fieldvision/io/source_backends.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::io::backend {
namespace {

// Live: frame k is captured at start + k / fps (given start_at_s: frames 0..N-1, then the end)
// or, without a start, on the world's clock: at Unix time t every synth camera of the scene sees
// scene frame floor(t fps) mod N (the scene loops), so nodes started at different moments agree.
class SynthLiveSource : public FrameSource {
 public:
  SynthLiveSource(const std::string& spec, const synth::SceneSpec& scene, int camera,
                  const FrameSourceOptions& o)
      : spec_(spec), encoded_(o.encoded), start_s_(o.start_at_s), buffer_(o.live_buffer_frames) {
    synth::SceneSpec one = scene;
    one.cameras = {scene.cameras[camera]};
    renderer_ = std::make_unique<synth::SceneRenderer>(one);
    quality_ = scene.jpeg_quality;
  }
  bool ReadFrame(SourceFrame* out) override {
    const double fps = renderer_->fps();
    const long long n = renderer_->num_frames();
    const double now = SystemClockNow();
    // The newest frame captured by now, in this source's numbering of capture instants.
    const long long newest = static_cast<long long>(std::floor((now - start_s_) * fps));
    if (next_ < 0) next_ = start_s_ > 0 ? 0 : std::max(0LL, newest);  // looping: join now
    long long oldest = newest - buffer_ + 1;                          // older frames are gone
    if (start_s_ > 0) oldest = std::min(oldest, n);
    if (next_ < oldest) {
      dropped_ += oldest - next_;
      next_ = oldest;
    }
    if (start_s_ > 0 && next_ >= n) return false;
    if (first_ < 0) first_ = next_;
    const double capture_s = start_s_ + next_ / fps;
    const int scene_frame = static_cast<int>(next_ % n);
    const cv::Mat bgr = renderer_->RenderCamera(0, scene_frame);
    out->bgr = cv::Mat();
    out->jpeg.clear();
    if (encoded_) {
      codecs::ImEncode(".jpg", bgr, &out->jpeg, {cv::IMWRITE_JPEG_QUALITY, quality_});
    } else {
      out->bgr = bgr;
    }
    const double wait_s = capture_s - SystemClockNow();
    if (wait_s > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
    out->frame = start_s_ > 0 ? next_ : next_ - first_;  // from a given start: the scene's frame
    out->time_s = capture_s;
    out->origin = TimeOrigin::kPlayback;
    ++next_;
    return true;
  }
  long long FrameCount() const override { return start_s_ > 0 ? renderer_->num_frames() : -1; }
  cv::Size FrameSize() const override {
    const camera::Camera& c = renderer_->cameras()[0];
    return {c.width, c.height};
  }
  std::string name() const override { return spec_; }
  double fps() const override { return renderer_->fps(); }
  bool live() const override { return true; }
  bool encoded() const override { return encoded_; }
  long long dropped() const override { return dropped_; }

 private:
  std::string spec_;
  bool encoded_;
  double start_s_;  // 0: the world's clock (see above)
  long long buffer_;
  int quality_ = 90;
  std::unique_ptr<synth::SceneRenderer> renderer_;
  long long next_ = -1;   // capture instant of the next frame
  long long first_ = -1;  // of the first frame delivered
  long long dropped_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> OpenSynth(const std::string& spec, const FrameSourceOptions& options) {
  const std::string rest = spec.substr(6);
  const size_t q = rest.find('?');
  const std::string scene_name = rest.substr(0, q);
  FV_REQUIRE(!scene_name.empty(), "video '{}': give a preset or scene file after 'synth:'", spec);
  std::map<std::string, std::string> params;
  if (q != std::string::npos) {
    for (const std::string& kv : util::Split(rest.substr(q + 1), '&')) {
      if (kv.empty()) continue;
      const size_t eq = kv.find('=');
      FV_REQUIRE(eq != std::string::npos, "video '{}': parameter '{}' has no value", spec, kv);
      params[kv.substr(0, eq)] = kv.substr(eq + 1);
    }
  }
  auto take_int = [&](const char* key, long long fallback) {
    const auto it = params.find(key);
    if (it == params.end()) return fallback;
    const long long v = util::ParseInt(it->second, fmt::format("'{}' in video '{}'", key, spec));
    params.erase(it);
    return v;
  };
  const long long seed = take_int("seed", 1);
  const long long width = take_int("width", 0);
  const long long height = take_int("height", 0);
  const long long frames = take_int("frames", 0);
  std::string camera_key;
  if (auto it = params.find("camera"); it != params.end()) {
    camera_key = it->second;
    params.erase(it);
  }
  FV_REQUIRE(params.empty(),
             "video '{}': unknown parameter '{}' (known: camera, seed, width, "
             "height, frames)",
             spec, params.begin()->first);
  synth::SceneSpec scene;
  if (std::filesystem::is_regular_file(scene_name)) {
    scene = synth::ReadSceneSpec(scene_name);
  } else {
    bool known = false;
    std::string names;
    for (const std::string& p : synth::PresetNames()) {
      known = known || p == scene_name;
      names += (names.empty() ? "" : ", ") + p;
    }
    FV_REQUIRE(known, "video '{}': '{}' is neither a scene file nor a preset ({})", spec,
               scene_name, names);
    scene = synth::Preset(scene_name, static_cast<uint64_t>(seed));
  }
  if (width > 0 || height > 0) {
    FV_REQUIRE(width > 0 && height > 0, "video '{}': give both width and height", spec);
    synth::ResizeCameras(scene, static_cast<int>(width), static_cast<int>(height));
  }
  if (frames > 0) scene.num_frames = static_cast<int>(frames);
  scene.Check();
  int camera = 0;
  if (!camera_key.empty()) {
    camera = -1;
    for (size_t c = 0; c < scene.cameras.size(); ++c) {
      if (scene.cameras[c].name == camera_key) camera = static_cast<int>(c);
    }
    if (camera < 0 && !camera_key.empty() &&
        camera_key.find_first_not_of("0123456789") == std::string::npos) {
      camera = static_cast<int>(util::ParseInt(camera_key, "camera"));
    }
    FV_REQUIRE(camera >= 0 && camera < static_cast<int>(scene.cameras.size()),
               "video '{}': the scene has no camera '{}'", spec, camera_key);
  }
  return std::make_unique<SynthLiveSource>(spec, scene, camera, options);
}

}  // namespace fv::io::backend
