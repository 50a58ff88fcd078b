// Ball detection speed on a 1280x960 frame (a synthetic render of the "kick" scene when the synth
// module is built, else a drawn field with a ball): colour classification + blobs with the
// lookup table and scanlines (steps 1, 2, 4; exact and quantised tables), the full detector
// (with sub-pixel refinement), and the same job done with OpenCV (cvtColor to HSV + inRange +
// connectedComponentsWithStats on the full frame) as the baseline. The DNN path (--detector dnn
// and both, detect/dnn_ball.h) also reports `x_colour`, its speed over the colour detector's. Every
// benchmark reports frames/s and `x_opencv`, its speed-up over the baseline measured in the same
// process, both from the thread's CPU time (robust on a loaded machine). One thread
// (cv::setNumThreads(1)).
#include <algorithm>
#include <ctime>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/ball_fit.h"
#include "fieldvision/detect/blobs.h"
#include "fieldvision/detect/colour.h"
#include "fieldvision/detect/dnn_ball.h"
#include "fieldvision/detect/test_images.h"
#include "fieldvision/util/error.h"
#if __has_include("fieldvision/synth/synth.h")
#include "fieldvision/synth/synth.h"
#define FV_BENCH_HAVE_SYNTH 1
#endif

namespace {

// Thread CPU time: on a shared, loaded machine wall time mostly measures the other processes.
double CpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

struct BenchFrame {
  cv::Mat bgr;
  fv::camera::Camera camera;
  bool synthetic = false;
};

const BenchFrame& TestFrame() {
  static const BenchFrame kFrame = [] {
    cv::setNumThreads(1);
    BenchFrame f;
#ifdef FV_BENCH_HAVE_SYNTH
    fv::synth::SceneSpec spec = fv::synth::Preset("kick", 1);
    spec.cameras.resize(1);
    spec.num_frames = 60;
    fv::synth::SceneRenderer scene(spec);
    f.bgr = scene.Render(40)[0];
    f.camera = scene.cameras()[0];
    f.synthetic = true;
#else
    fv::util::Rng rng(1);
    f.bgr = fv::detect::test_util::FieldImage(1280, 960, rng);
    fv::detect::test_util::PaintDisc(f.bgr, Eigen::Vector2d(700.3, 500.6), 9.0);
    f.camera = fv::camera::Camera::FromFov(1280, 960, 75.0);
#endif
    return f;
  }();
  return kFrame;
}

// The OpenCV job: HSV conversion, the same orange range, 8-connected components with stats.
int OpenCvJob(const cv::Mat& bgr, cv::Mat& hsv, cv::Mat& mask, cv::Mat& labels, cv::Mat& stats,
              cv::Mat& centroids) {
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV_FULL);
  const fv::detect::ColourRange r = fv::detect::ColourPreset("orange").ranges[0];
  const auto h = [](double deg) { return deg * 256.0 / 360.0; };
  cv::inRange(hsv, cv::Scalar(h(r.min[0]), r.min[1], r.min[2]),
              cv::Scalar(h(r.max[0]), r.max[1], r.max[2]), mask);
  return cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
}

// Seconds per frame of the OpenCV job (median of 25 runs), measured once.
double BaselineSeconds() {
  static const double kSeconds = [] {
    const BenchFrame& f = TestFrame();
    cv::Mat hsv, mask, labels, stats, centroids;
    std::vector<double> t;
    for (int i = 0; i < 25; ++i) {
      const double t0 = CpuSeconds();
      benchmark::DoNotOptimize(OpenCvJob(f.bgr, hsv, mask, labels, stats, centroids));
      t.push_back(CpuSeconds() - t0);
    }
    std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
    return t[t.size() / 2];
  }();
  return kSeconds;
}

void SetCounters(benchmark::State& state, double total_s) {
  const double per_frame = total_s / std::max<int64_t>(state.iterations(), 1);
  state.counters["fps"] = 1.0 / per_frame;
  state.counters["x_opencv"] = BaselineSeconds() / per_frame;
  state.counters["opencv_fps"] = 1.0 / BaselineSeconds();
}

void BM_OpenCvInRangeComponents(benchmark::State& state) {
  const BenchFrame& f = TestFrame();
  BaselineSeconds();
  cv::Mat hsv, mask, labels, stats, centroids;
  double total = 0;
  for (auto _ : state) {
    const double t0 = CpuSeconds();
    benchmark::DoNotOptimize(OpenCvJob(f.bgr, hsv, mask, labels, stats, centroids));
    total += CpuSeconds() - t0;
  }
  SetCounters(state, total);
  state.SetLabel(f.synthetic ? "synth kick frame" : "drawn frame");
}
BENCHMARK(BM_OpenCvInRangeComponents)->Unit(benchmark::kMicrosecond);

// Lookup table + scanlines + runs + union-find. Args: step, bits per channel.
void BM_LutScanBlobs(benchmark::State& state) {
  const BenchFrame& f = TestFrame();
  BaselineSeconds();
  const int bits = static_cast<int>(state.range(1));
  const auto table = fv::detect::ColourTable::Shared(fv::detect::PresetColourSpec("orange"), bits);
  fv::detect::ScanOptions o;
  o.step_px = static_cast<int>(state.range(0));
  size_t blobs = 0;
  double total = 0;
  for (auto _ : state) {
    const double t0 = CpuSeconds();
    const fv::detect::BlobScanResult r = fv::detect::ScanBlobs(f.bgr, *table, table->BallBit(), o);
    total += CpuSeconds() - t0;
    blobs = r.blobs.size();
    benchmark::DoNotOptimize(blobs);
  }
  SetCounters(state, total);
  state.counters["blobs"] = static_cast<double>(blobs);
}
BENCHMARK(BM_LutScanBlobs)
    ->ArgNames({"step", "bits"})
    ->Args({1, 8})
    ->Args({2, 8})
    ->Args({4, 8})
    ->Args({2, 6})
    ->Args({4, 6})
    ->Args({2, 5})
    ->Unit(benchmark::kMicrosecond);

// The whole detector: blobs, filters, region check, sub-pixel refinement (calibrated camera);
// region:0 leaves the region stage out (its cost is the difference).
void BM_BallDetector(benchmark::State& state) {
  const BenchFrame& f = TestFrame();
  BaselineSeconds();
  fv::detect::BallDetectorOptions o;
  o.scan_step_px = static_cast<int>(state.range(0));
  o.use_region = state.range(1) != 0;
  const fv::detect::BallDetector det(o, &f.camera, nullptr);
  int accepted = 0;
  double total = 0;
  for (auto _ : state) {
    const double t0 = CpuSeconds();
    const auto r = det.DetectWithSummary(f.bgr);
    total += CpuSeconds() - t0;
    accepted = r.accepted();
  }
  SetCounters(state, total);
  state.counters["accepted"] = accepted;
}
BENCHMARK(BM_BallDetector)
    ->ArgNames({"step", "region"})
    ->Args({2, 1})
    ->Args({2, 0})
    ->Args({4, 1})
    ->Unit(benchmark::kMicrosecond);

// Without a camera (a photo) on a frame whose ball is painted over with grass: nothing is
// accepted, so the small-ball stage (detect/small_ball.h; "auto", the default without a camera,
// against "off") searches the whole frame, then the field check of its spots.
void BM_BallDetectorNoBallNoCamera(benchmark::State& state) {
  static const cv::Mat kNoBall = [] {
    fv::util::Rng rng(2);
    return fv::detect::test_util::FieldImage(1280, 960, rng);
  }();
  BaselineSeconds();
  fv::detect::BallDetectorOptions o;
  o.small.mode = state.range(0) != 0 ? "auto" : "off";
  const fv::detect::BallDetector det(o, nullptr, nullptr);
  int accepted = 0;
  double total = 0;
  for (auto _ : state) {
    const double t0 = CpuSeconds();
    accepted = det.DetectWithSummary(kNoBall).accepted();
    total += CpuSeconds() - t0;
  }
  SetCounters(state, total);
  state.counters["accepted"] = accepted;
}
BENCHMARK(BM_BallDetectorNoBallNoCamera)
    ->ArgNames({"small"})
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond);

// The sub-pixel outline fit alone (detect/ball_fit.h, with the camera) on each candidate the
// detector refines in the frame, seeded at the candidate's centre and radius: most of the
// detector's time after the region stage.
void BM_BallFit(benchmark::State& state) {
  const BenchFrame& f = TestFrame();
  BaselineSeconds();
  const fv::detect::BallDetectorOptions o;
  const fv::detect::BallDetector det(o, &f.camera, nullptr);
  const auto table = fv::detect::ColourTable::Shared(fv::detect::PresetColourSpec("orange"));
  std::vector<fv::detect::BallCandidate> seeds;
  for (const auto& c : det.DetectWithSummary(f.bgr).candidates) {
    if (c.radius_px >= 0.5 * o.min_radius_px) seeds.push_back(c);
  }
  int ok = 0;
  double total = 0;
  for (auto _ : state) {
    const double t0 = CpuSeconds();
    ok = 0;
    for (const auto& c : seeds) {
      ok += fv::detect::FitBall(f.bgr, *table, table->BallBit(), c.centre_px, c.radius_px,
                                &f.camera, o.fit)
                .ok;
    }
    total += CpuSeconds() - t0;
  }
  SetCounters(state, total);
  state.counters["fits"] = static_cast<double>(seeds.size());
  state.counters["ok"] = ok;
}
BENCHMARK(BM_BallFit)->Unit(benchmark::kMicrosecond);

// Seconds per frame of the colour detector (step 2, region stage on; median of 9 runs), once.
double ColourSeconds() {
  static const double kSeconds = [] {
    const BenchFrame& f = TestFrame();
    const fv::detect::BallDetector det(fv::detect::BallDetectorOptions(), &f.camera, nullptr);
    std::vector<double> t;
    for (int i = 0; i < 9; ++i) {
      const double t0 = CpuSeconds();
      benchmark::DoNotOptimize(det.Detect(f.bgr).size());
      t.push_back(CpuSeconds() - t0);
    }
    std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
    return t[t.size() / 2];
  }();
  return kSeconds;
}

// The DNN path on the same frame (one thread). Args: mode (1 dnn, 2 both), whole_frame (both:
// also the whole-frame search; dnn always searches the whole frame, at the frame's width).
void BM_DnnBallDetector(benchmark::State& state) {
  const BenchFrame& f = TestFrame();
  BaselineSeconds();
  fv::detect::DnnBallOptions o;
  o.detector = state.range(0) == 1 ? "dnn" : "both";
  o.whole_frame = state.range(1) != 0;
  std::unique_ptr<fv::detect::AnyBallDetector> det;
  try {
    det = std::make_unique<fv::detect::AnyBallDetector>(fv::detect::BallDetectorOptions(), o,
                                                        &f.camera, nullptr);
  } catch (const fv::Error& e) {
    state.SkipWithError(e.what());  // the model is made by `make build`
    return;
  }
  const double colour_s = ColourSeconds();
  int accepted = 0;
  double total = 0;
  for (auto _ : state) {
    const double t0 = CpuSeconds();
    const auto cands = det->Detect(f.bgr);
    total += CpuSeconds() - t0;
    accepted = static_cast<int>(
        std::count_if(cands.begin(), cands.end(), [](const auto& c) { return c.accepted; }));
  }
  SetCounters(state, total);
  const double per_frame = total / std::max<int64_t>(state.iterations(), 1);
  state.counters["ms"] = 1e3 * per_frame;
  state.counters["x_colour"] = colour_s / per_frame;
  state.counters["colour_ms"] = 1e3 * colour_s;
  state.counters["accepted"] = accepted;
}
BENCHMARK(BM_DnnBallDetector)
    ->ArgNames({"mode", "whole"})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Args({2, 0})
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
