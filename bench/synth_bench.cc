// Speed of the synthetic world: rendering one 1280x960 camera frame of the kick preset, against
// the baseline of copying and noising nothing but the background (the least any renderer must do:
// touch every pixel once), and MJPG-encoding a frame (what writing the video adds).
#include <benchmark/benchmark.h>

#include <memory>
#include <opencv2/imgcodecs.hpp>

#include "fieldvision/synth/synth.h"
#include "times_reporter.h"

namespace {

const fv::synth::SceneRenderer& Scene() {
  static const auto kScene = [] {
    fv::synth::SceneSpec s = fv::synth::Preset("kick", 1);
    return std::make_unique<fv::synth::SceneRenderer>(s);
  }();
  return *kScene;
}

// Baseline: copy the background image (one pass over the pixels).
void BM_BackgroundCopy(benchmark::State& state) {
  const cv::Mat& bg = Scene().Background(0);
  for (auto _ : state) {
    cv::Mat img = bg.clone();
    benchmark::DoNotOptimize(img.data);
  }
  state.counters["px"] = bg.total();
}
BENCHMARK(BM_BackgroundCopy)->Unit(benchmark::kMillisecond);

// A full frame of one camera: objects, ball with motion blur, shadows, lighting, noise.
void BM_RenderCameraFrame(benchmark::State& state) {
  const auto& scene = Scene();
  int frame = 0;
  for (auto _ : state) {
    cv::Mat img = scene.RenderCamera(0, 30 + frame);
    benchmark::DoNotOptimize(img.data);
    frame = (frame + 1) % 120;
  }
}
BENCHMARK(BM_RenderCameraFrame)->Unit(benchmark::kMillisecond);

// JPEG encoding of a frame at the preset's quality (MJPG writing does this per frame).
void BM_JpegEncode(benchmark::State& state) {
  const cv::Mat img = Scene().RenderCamera(0, 40);
  std::vector<uchar> buf;
  for (auto _ : state) {
    cv::imencode(".jpg", img, buf, {cv::IMWRITE_JPEG_QUALITY, 90});
    benchmark::DoNotOptimize(buf.data());
  }
}
BENCHMARK(BM_JpegEncode)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  Scene();  // set-up outside the timings
  fv::bench::TimesReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.PrintRatios("BM_BackgroundCopy", "the background copy");
  return 0;
}
