// Robustness of the ball detector on the real photos (shared/data/robocup-ball-photos): the score
// of `eval detect` (best accepted candidate per image, hit inside the box grown by 25 %) on the
// photos as they are and on copies changed as other cameras and other photos of the same kinds
// differ: JPEG re-encoded (quality 95 and 60), scaled (0.8, 1.25), darker and brighter (x0.85,
// x1.15), another white balance (blue x1.08, red x0.93) and a slight defocus (Gaussian sigma
// 0.7 px). Each variant reports recall, precision and their ratios to the photos as they are,
// measured in the same process; the last lines give the mean over the changed copies. A decision
// that sits on a threshold flips under such changes: a score that holds on the originals alone
// will not hold on other photos. `--detector=colour|both` (default both, as `eval detect` on
// still images; colour without the model). One benchmark runs a whole set once (MSL about 25 s,
// SSL about 40 s a variant with both). `--step=N` sets the scanline step (default: eval detect's).
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/detect_eval.h"
#include "fieldvision/dnn/nanodet.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace {

struct PhotoSet {
  const char* name;
  const char* images;  // relative to shared/data/robocup-ball-photos
  const char* labels;  // "" = beside the images
  int class_id;
  const char* colour;
};

const PhotoSet kSets[] = {{"msl", "msl-yellow", "", 0, "yellow"},
                          {"ssl", "ssl-orange/images", "ssl-orange/labels", 1, "orange"}};

struct Variant {
  const char* name;
  std::function<cv::Mat(const cv::Mat&)> transform;  // empty: the photos as they are
};

cv::Mat Jpeg(const cv::Mat& bgr, int quality) {
  std::vector<uchar> bytes;
  cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
  return cv::imdecode(bytes, cv::IMREAD_COLOR);
}

cv::Mat Scaled(const cv::Mat& bgr, double s) {
  cv::Mat out;
  cv::resize(bgr, out, cv::Size(), s, s, s < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out;
}

cv::Mat Gains(const cv::Mat& bgr, double b, double g, double r) {
  cv::Mat out;
  cv::multiply(bgr, cv::Scalar(b, g, r), out);  // saturates at 255
  return out;
}

cv::Mat Defocused(const cv::Mat& bgr) {
  cv::Mat out;
  cv::GaussianBlur(bgr, out, cv::Size(0, 0), 0.7);
  return out;
}

const std::vector<Variant>& Variants() {
  static const std::vector<Variant> kVariants = {
      {"original", {}},
      {"jpeg95", [](const cv::Mat& m) { return Jpeg(m, 95); }},
      {"jpeg60", [](const cv::Mat& m) { return Jpeg(m, 60); }},
      {"scale0.8", [](const cv::Mat& m) { return Scaled(m, 0.8); }},
      {"scale1.25", [](const cv::Mat& m) { return Scaled(m, 1.25); }},
      {"gain0.85", [](const cv::Mat& m) { return Gains(m, 0.85, 0.85, 0.85); }},
      {"gain1.15", [](const cv::Mat& m) { return Gains(m, 1.15, 1.15, 1.15); }},
      {"white_balance", [](const cv::Mat& m) { return Gains(m, 1.08, 1.0, 0.93); }},
      {"defocus", Defocused},
  };
  return kVariants;
}

// A run's recall and precision (DetectEvalResult::recall, precision).
struct Score {
  double recall = 0.0, precision = 0.0;
};

std::map<std::string, Score>& Originals() {
  static std::map<std::string, Score> scores;
  return scores;
}

std::map<std::string, std::vector<Score>>& Changed() {
  static std::map<std::string, std::vector<Score>> scores;
  return scores;
}

// --detector=colour|both (before the benchmark's own flags); without it both, or colour when
// the NanoDet model is missing.
std::string& DetectorChoice() {
  static std::string choice;
  return choice;
}

// --step=N: the scanline step (BallDetectorOptions::scan_step_px; default that of `eval detect`).
int& StepChoice() {
  static int step = 0;
  return step;
}

std::string DefaultDetector() {
  try {
    fv::dnn::FindModel("nanodet.onnx");
    return "both";
  } catch (const fv::Error&) {
    return "colour";
  }
}

void BM_PhotoVariant(benchmark::State& state, const PhotoSet& set, const Variant& variant) {
  const std::string root = std::string(FV_SHARED_DATA_DIR) + "/robocup-ball-photos/";
  fv::detect::DetectEvalOptions o;
  o.video = root + set.images;
  o.labels.labels = *set.labels != '\0' ? root + set.labels : "";
  o.labels.class_id = set.class_id;
  o.detector.colour = set.colour;
  o.dnn.detector = DetectorChoice();
  if (StepChoice() > 0) o.detector.scan_step_px = StepChoice();
  o.progress = false;
  o.transform = variant.transform;
  fv::detect::DetectEvalResult r;
  for (auto _ : state) {
    try {
      r = fv::detect::EvaluateDetector(o);
    } catch (const fv::Error& e) {
      state.SkipWithError(e.what());
      return;
    }
  }
  const Score s{r.recall(), r.precision()};
  state.counters["recall"] = s.recall;
  state.counters["precision"] = s.precision;
  state.counters["images_per_s"] = r.seconds > 0 ? r.images.size() / r.seconds : 0.0;
  if (!variant.transform) {
    Originals()[set.name] = s;
    return;
  }
  Changed()[set.name].push_back(s);
  const auto orig = Originals().find(set.name);
  if (orig != Originals().end() && orig->second.recall > 0 && orig->second.precision > 0) {
    state.counters["recall_x_orig"] = s.recall / orig->second.recall;
    state.counters["precision_x_orig"] = s.precision / orig->second.precision;
  }
}

void RegisterAll() {
  for (const PhotoSet& set : kSets) {
    for (const Variant& v : Variants()) {
      benchmark::RegisterBenchmark((std::string("BM_Photos/") + set.name + "/" + v.name).c_str(),
                                   BM_PhotoVariant, set, v)
          ->Iterations(1)
          ->Unit(benchmark::kSecond);
    }
  }
}

// The mean recall and precision over the changed copies run, against the originals.
void PrintMeans() {
  for (const auto& [name, scores] : Changed()) {
    std::vector<double> recalls, precisions;
    for (const Score& s : scores) {
      recalls.push_back(s.recall);
      precisions.push_back(s.precision);
    }
    const auto orig = Originals().find(name);
    std::printf("%s: %zu changed copies, mean recall %.3f, mean precision %.3f", name.c_str(),
                scores.size(), fv::util::Mean(recalls), fv::util::Mean(precisions));
    if (orig != Originals().end()) {
      std::printf(" (originals %.3f / %.3f)", orig->second.recall, orig->second.precision);
    }
    std::printf("\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  DetectorChoice() = DefaultDetector();
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--step=", 0) == 0) {
      StepChoice() = std::atoi(arg.c_str() + 7);
      if (StepChoice() < 1 || StepChoice() > 16) {
        std::fprintf(stderr, "bench_photo_robustness: --step must be 1..16 (got %s)\n",
                     arg.c_str() + 7);
        return 1;
      }
      continue;
    }
    if (arg.rfind("--detector=", 0) != 0) {
      args.push_back(argv[i]);
      continue;
    }
    DetectorChoice() = arg.substr(11);
    if (DetectorChoice() != "colour" && DetectorChoice() != "both") {
      std::fprintf(stderr, "bench_photo_robustness: --detector must be colour or both (got %s)\n",
                   DetectorChoice().c_str());
      return 1;
    }
  }
  int n = static_cast<int>(args.size());
  RegisterAll();
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 1;
  std::printf("detector: %s%s\n", DetectorChoice().c_str(),
              StepChoice() > 0 ? fmt::format(", scanline step {} px", StepChoice()).c_str() : "");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  PrintMeans();
  return 0;
}
