// Frame-source backend: a synthetic scene played live, "synth:PRESET_OR_SCENE.json?camera=NAME
// &seed=N&width=W&height=H&frames=N" (the parameters of `fieldvision synth`; camera: a name or an
// index, default the first). Frames are rendered on demand (synth/synth.h), JPEG-compressed at
// the scene's quality when encoded frames are asked for, and delivered at the scene's frame rate
// as a camera would (paced_source.cc), so a camera node can be tested without a camera.
#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "fieldvision/io/source_backends.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::io_backend {
namespace {

class SynthSceneSource : public FrameSource {
 public:
  SynthSceneSource(const std::string& spec, const synth::SceneSpec& scene, int camera, bool encoded)
      : spec_(spec), encoded_(encoded) {
    synth::SceneSpec one = scene;
    one.cameras = {scene.cameras[camera]};
    renderer_ = std::make_unique<synth::SceneRenderer>(one);
    quality_ = scene.jpeg_quality;
  }
  bool ReadFrame(SourceFrame* out) override {
    if (next_ >= renderer_->num_frames()) return false;
    const cv::Mat bgr = renderer_->RenderCamera(0, static_cast<int>(next_));
    out->bgr = cv::Mat();
    out->jpeg.clear();
    if (encoded_) {
      cv::imencode(".jpg", bgr, out->jpeg, {cv::IMWRITE_JPEG_QUALITY, quality_});
    } else {
      out->bgr = bgr;
    }
    out->frame = next_;
    out->time_s = renderer_->FrameTime(static_cast<int>(next_));
    out->origin = TimeOrigin::kFrameRate;
    ++next_;
    return true;
  }
  long long FrameCount() const override { return renderer_->num_frames(); }
  cv::Size FrameSize() const override {
    const Camera& c = renderer_->cameras()[0];
    return {c.width, c.height};
  }
  std::string name() const override { return spec_; }
  double fps() const override { return renderer_->fps(); }
  bool encoded() const override { return encoded_; }

 private:
  std::string spec_;
  bool encoded_;
  int quality_ = 90;
  std::unique_ptr<synth::SceneRenderer> renderer_;
  long long next_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> OpenSynth(const std::string& spec, const FrameSourceOptions& options) {
  const std::string rest = spec.substr(6);
  const size_t q = rest.find('?');
  const std::string scene_name = rest.substr(0, q);
  FV_REQUIRE(!scene_name.empty(), "video '{}': give a preset or scene file after 'synth:'", spec);
  std::map<std::string, std::string> params;
  if (q != std::string::npos) {
    for (const std::string& kv : Split(rest.substr(q + 1), '&')) {
      if (kv.empty()) continue;
      const size_t eq = kv.find('=');
      FV_REQUIRE(eq != std::string::npos, "video '{}': parameter '{}' has no value", spec, kv);
      params[kv.substr(0, eq)] = kv.substr(eq + 1);
    }
  }
  auto take_int = [&](const char* key, long long fallback) {
    const auto it = params.find(key);
    if (it == params.end()) return fallback;
    const long long v = ParseInt(it->second, fmt::format("'{}' in video '{}'", key, spec));
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
  if (std::filesystem::exists(scene_name)) {
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
      camera = static_cast<int>(ParseInt(camera_key, "camera"));
    }
    FV_REQUIRE(camera >= 0 && camera < static_cast<int>(scene.cameras.size()),
               "video '{}': the scene has no camera '{}'", spec, camera_key);
  }
  auto source = std::make_unique<SynthSceneSource>(spec, scene, camera, options.encoded);
  return Paced(std::move(source), options);
}

}  // namespace fv::io_backend
