// Cost of re-upsampling a frame's repeated chroma (repeated_chroma.h) on a 1280x960 kick frame
// as OpenCV's FFmpeg reader delivers MPEG-4 video (chroma repeated over 2x2 pixels),
// against the baselines of copying the frame (touching every pixel once) and one OpenCV colour
// conversion (BGR -> YCrCb), and measuring the layout (done on a stream's first frames only).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <unistd.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/io/io_testing.h"
#include "fieldvision/io/repeated_chroma.h"
#include "fieldvision/synth/synth.h"
#include "times_reporter.h"

namespace {

// A kick frame written as MPEG-4 (4:2:0) and read back by OpenCV's FFmpeg reader, which repeats
// its chroma over 2x2 pixels (what the frame sources repair); where OpenCV cannot write MPEG-4,
// the frame with its chroma decimated and repeated in memory (noisier chroma: more to repair).
const cv::Mat& Frame() {
  static const cv::Mat kFrame = [] {
    const fv::synth::SceneRenderer scene(fv::synth::Preset("kick", 1));
    const cv::Mat rendered = scene.RenderCamera(0, 40);
    const std::string path =
        (std::filesystem::temp_directory_path() / fmt::format("fv_chroma_{}.mp4", ::getpid()))
            .string();
    cv::Mat decoded;
    {
      cv::VideoWriter w(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), 30,
                        rendered.size());
      if (w.isOpened()) w.write(rendered);
    }
    cv::VideoCapture(path, cv::CAP_FFMPEG).read(decoded);
    std::filesystem::remove(path);
    if (decoded.empty()) {
      std::printf("MPEG-4 not written here: chroma repeated in memory\n");
      return fv::io::test_util::RepeatChroma2x2(rendered);
    }
    return decoded;
  }();
  return kFrame;
}

void BM_FrameCopy(benchmark::State& state) {
  cv::Mat img;
  for (auto _ : state) {
    Frame().copyTo(img);
    benchmark::DoNotOptimize(img.data);
  }
}
BENCHMARK(BM_FrameCopy)->Unit(benchmark::kMillisecond);

void BM_CvtColorYCrCb(benchmark::State& state) {
  cv::Mat out;
  for (auto _ : state) {
    cv::cvtColor(Frame(), out, cv::COLOR_BGR2YCrCb);
    benchmark::DoNotOptimize(out.data);
  }
}
BENCHMARK(BM_CvtColorYCrCb)->Unit(benchmark::kMillisecond);

void BM_MeasureChromaLayout(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(fv::io::MeasureChromaLayout(Frame()));
}
BENCHMARK(BM_MeasureChromaLayout)->Unit(benchmark::kMillisecond);

// Copy + re-upsampling with a stream's kept buffers (the copy keeps every iteration's input the
// same).
void BM_UpsampleRepeatedChroma(benchmark::State& state) {
  fv::io::ChromaWorkspace workspace;
  cv::Mat img;
  for (auto _ : state) {
    Frame().copyTo(img);
    fv::io::UpsampleRepeatedChroma(&img, {}, &workspace);
    benchmark::DoNotOptimize(img.data);
  }
}
BENCHMARK(BM_UpsampleRepeatedChroma)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  Frame();  // set-up outside the timings
  fv::bench::TimesReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.PrintRatios("BM_FrameCopy", "the frame copy");
  return 0;
}
