// What one camera node does per frame, on one core (issue 14's throughput: 4 cameras x 1280x960 x
// 60 fps on 2 cores): the camera stage (pipeline/camera_stage.h) on the synthetic "kick" scene's
// first camera at 1280x960, JPEG frames as a Motion-JPEG camera or `synth:` delivers them,
// decoded only around the tracked ball (and whole every full_scan_every frames or when the ball is
// lost), then the frame message encoded as the node sends it. Against the same frames decoded
// whole (the baseline, measured in the same process), the stage searching every frame whole, and
// the stage's search for other balls (the whole frame every 20 frames) split into 2 or 20 bands
// of rows, one a frame (--scan-bands; `p95_ms`, `max_ms`: the peaks of work per frame).
// The decoding alone: whole, and a window at the top, middle and bottom of the frame.
// Counters from the thread's CPU time (robust on a loaded machine): ms per frame and
// `cores_4x60`, the cores 4 cameras at 60 fps need for this work (2 cores: must stay under 2,
// with room for the fusion node and the system). One thread (cv::setNumThreads(1)).
#include <algorithm>
#include <ctime>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/io/jpeg_region.h"
#include "fieldvision/net/messages.h"
#include "fieldvision/pipeline/ball_job.h"
#include "fieldvision/pipeline/camera_stage.h"
#include "fieldvision/synth/synth.h"

namespace {

double CpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

struct Clip {
  fv::camera::Camera camera;
  std::vector<fv::io::SourceFrame> frames;  // JPEG, in order
};

// Frames 10..69 of the kick scene (rest, the kick at 0.25 s, the flight), camera 1, 1280x960.
const Clip& KickClip() {
  static const Clip kClip = [] {
    cv::setNumThreads(1);
    fv::synth::SceneSpec spec = fv::synth::Preset("kick", 1);
    fv::synth::ResizeCameras(spec, 1280, 960);
    fv::synth::SceneRenderer scene(spec);
    Clip c;
    c.camera = scene.cameras()[0];
    for (int f = 10; f < 70; ++f) {
      fv::io::SourceFrame s;
      cv::imencode(".jpg", scene.RenderCamera(0, f), s.jpeg,
                   {cv::IMWRITE_JPEG_QUALITY, spec.jpeg_quality});
      s.frame = f;
      s.time_s = f / spec.fps;
      c.frames.push_back(std::move(s));
    }
    return c;
  }();
  return kClip;
}

double BaselineSeconds() {  // whole decode of one frame, median of 3 passes
  static const double kSeconds = [] {
    const Clip& c = KickClip();
    fv::io::JpegRegionDecoder decoder;
    cv::Mat bgr;
    std::vector<double> t;
    for (int pass = 0; pass < 3; ++pass) {
      const double t0 = CpuSeconds();
      for (const auto& f : c.frames) {
        decoder.Decode(f.jpeg.data(), f.jpeg.size(), cv::Rect(), &bgr, "bench frame");
      }
      t.push_back((CpuSeconds() - t0) / c.frames.size());
    }
    std::sort(t.begin(), t.end());
    return t[1];
  }();
  return kSeconds;
}

void SetCounters(benchmark::State& state, double total_s) {
  const double per_frame = total_s / std::max<int64_t>(state.iterations(), 1);
  state.counters["ms_per_frame"] = 1e3 * per_frame;
  state.counters["cores_4x60"] = 4 * 60 * per_frame;
  state.counters["x_decode_whole"] = per_frame / BaselineSeconds();
}

void BM_DecodeWhole(benchmark::State& state) {
  const Clip& c = KickClip();
  fv::io::JpegRegionDecoder decoder;
  cv::Mat bgr;
  size_t i = 0;
  double total = 0;
  for (auto _ : state) {
    const auto& f = c.frames[i++ % c.frames.size()];
    const double t0 = CpuSeconds();
    decoder.Decode(f.jpeg.data(), f.jpeg.size(), cv::Rect(), &bgr, "bench frame");
    total += CpuSeconds() - t0;
  }
  SetCounters(state, total);
}
BENCHMARK(BM_DecodeWhole)->Unit(benchmark::kMillisecond);

// An 80 x 80 window (a tracked ball) whose top is at state.range(0) % of the frame's height: the
// rows above it are entropy-decoded all the same (a JPEG without restart markers has no other way
// to reach them), only the inverse DCT and colour conversion are saved; this bounds what tracking
// can save on decoding.
void BM_DecodeWindow(benchmark::State& state) {
  const Clip& c = KickClip();
  fv::io::JpegRegionDecoder decoder;
  cv::Mat bgr;
  const cv::Rect window(600, static_cast<int>(state.range(0) * (c.camera.height - 80) / 100), 80,
                        80);
  size_t i = 0;
  double total = 0;
  for (auto _ : state) {
    const auto& f = c.frames[i++ % c.frames.size()];
    const double t0 = CpuSeconds();
    decoder.Decode(f.jpeg.data(), f.jpeg.size(), window, &bgr, "bench frame");
    total += CpuSeconds() - t0;
  }
  SetCounters(state, total);
  state.SetLabel(fmt::format("window rows {}..{}", window.y, window.y + window.height));
}
BENCHMARK(BM_DecodeWindow)->Arg(0)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond);

// state.range(0): 0 every frame whole, else the tracking window and the whole frame every 20
// frames in this many bands (1: the node's default).
void BM_NodeFrame(benchmark::State& state) {
  const Clip& c = KickClip();
  const fv::detect::BallDetectorOptions defaults;
  const fv::detect::BallDetectorOptions dopt =
      fv::pipeline::TrackingDetectorOptions(defaults.diameter_m, defaults.colour);
  auto detector = std::make_shared<fv::detect::BallDetector>(dopt, &c.camera, nullptr);
  fv::pipeline::BallTrackOptions track;
  track.enabled = state.range(0) != 0;
  track.scan_bands = std::max<int>(1, state.range(0));
  std::vector<double> frame_s;
  std::unique_ptr<fv::pipeline::CameraStage> stage;
  fv::net::FrameMessage m;
  m.camera = "cam1";
  m.session = "bench";
  m.origin = "playback";
  size_t i = 0;
  double total = 0;
  long long full = 0, window = 0;
  for (auto _ : state) {
    if (i % c.frames.size() == 0) {  // each pass through the clip starts a fresh stage
      if (stage) full += stage->stats().full_scans, window += stage->stats().window_scans;
      stage = std::make_unique<fv::pipeline::CameraStage>(
          0, c.camera, fv::pipeline::BallDetectFnFor(detector), track, "bench");
    }
    const auto& f = c.frames[i++ % c.frames.size()];
    const double t0 = CpuSeconds();
    fv::pipeline::CameraMessage cm = stage->Process(f);
    m.frame = cm.frame;
    m.time_s = cm.time_s;
    m.candidates = std::move(cm.candidates);
    benchmark::DoNotOptimize(fv::net::Encode(m));
    frame_s.push_back(CpuSeconds() - t0);
    total += frame_s.back();
  }
  full += stage->stats().full_scans, window += stage->stats().window_scans;
  SetCounters(state, total);
  std::sort(frame_s.begin(), frame_s.end());
  state.counters["p95_ms"] = 1e3 * frame_s[frame_s.size() * 95 / 100];
  state.counters["max_ms"] = 1e3 * frame_s.back();
  state.counters["whole_share"] = static_cast<double>(full) / std::max(1LL, full + window);
  state.SetLabel(!track.enabled ? "whole frames"
                                : fmt::format("tracking window, {} bands", track.scan_bands));
}
BENCHMARK(BM_NodeFrame)->Arg(1)->Arg(2)->Arg(20)->Arg(0)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
