// `fieldvision synth`: render a synthetic scene (preset or scene JSON) with exact ground truth.
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "fieldvision/app/command.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/error.h"

namespace fv::app {
namespace {

struct SynthOptions {
  std::string preset;
  std::string scene;
  std::string out;
  std::optional<uint64_t> seed;
  std::optional<int> frames;
  std::optional<int> width, height;
  std::string format;
  bool quiet = false;
};

void RunSynth(const SynthOptions& o) {
  FV_REQUIRE(o.preset.empty() != o.scene.empty(), "synth: give exactly one of --preset or --scene");
  FV_REQUIRE(o.scene.empty() || !std::filesystem::is_directory(o.scene),
             "synth: --scene '{}' is a folder, not a scene JSON file", o.scene);
  synth::SceneSpec spec =
      o.scene.empty() ? synth::Preset(o.preset, o.seed.value_or(1)) : synth::ReadSceneSpec(o.scene);
  if (o.seed) spec.seed = *o.seed;
  if (o.frames) spec.num_frames = *o.frames;
  FV_REQUIRE(o.width.has_value() == o.height.has_value(), "synth: give both --width and --height");
  if (o.width) synth::ResizeCameras(spec, *o.width, *o.height);
  // Memory: rendering takes about 37 bytes per pixel of all cameras (2.5 GB for 4 x 16.8 Mpx);
  // 40 Mpx in all (four 4K cameras) stays near 1.5 GB.
  int64_t pixels = 0;
  for (const auto& c : spec.cameras) pixels += int64_t{c.width} * c.height;
  FV_REQUIRE(pixels <= 40'000'000,
             "synth: the {} cameras of {} hold {:.1f} megapixels in all (at most 40: smaller "
             "--width/--height)",
             spec.cameras.size(), o.scene.empty() ? "--preset " + o.preset : o.scene, pixels / 1e6);
  if (!o.format.empty()) spec.format = o.format;
  spec.Check();
  const synth::WriteSceneResult r = synth::WriteScene(spec, o.out, !o.quiet);
  for (const auto& f : r.files) std::cout << "wrote " << f << "\n";
  std::cout << r.Summary() << "\n";
}

void Setup(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<SynthOptions>();
  CLI::App* cmd = app.add_subcommand(
      "synth",
      "Render a synthetic scene: N calibrated cameras, a ball (placed or kicked with bounces), "
      "robots, people, a cone; writes videos, camera YAMLs and exact truth");
  cmd->add_option("--preset", o->preset,
                  "static | kick | players | demo | low-sun (static, sun 30 deg high, far side "
                  "of the ball at 35 %, printed yellow ball, exposure and white-balance drift) | "
                  "low-sun-kick (kick in that light, ball spinning) | fisheye (130 deg lenses, "
                  "balls near cam1's border) | held (a ball in a robot's handler)");
  cmd->add_option("--scene", o->scene, "Scene JSON (see scene.json written by a preset)");
  cmd->add_option("--out", o->out, "Output folder (created)")->required();
  cmd->add_option("--seed", o->seed, "Random seed (placements, paths, noise)")->check(Seed());
  cmd->add_option("--frames", o->frames, "Number of frames")->check(CLI::Range(1, 1000000));
  cmd->add_option("--width", o->width, "Image width of every camera (at most 8192)")
      ->check(CLI::Range(16, 8192));
  cmd->add_option("--height", o->height, "Image height of every camera (at most 8192)")
      ->check(CLI::Range(16, 8192));
  cmd->add_option("--format", o->format,
                  "avi (MJPG) | mp4 (H.264 at the encoder's default quality, as most cameras' "
                  "footage: what compression costs) | png | jpg (image sequences)")
      ->check(CLI::IsMember({"avi", "mp4", "png", "jpg"}));
  cmd->add_flag("--quiet", o->quiet, "No progress line");
  cmd->callback([o] { RunSynth(*o); });
  (void)exit_code;
}

FV_REGISTER_COMMAND(10, "synth", Setup);

}  // namespace
}  // namespace fv::app
