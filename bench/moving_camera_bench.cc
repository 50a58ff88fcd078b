// Players with a moving camera on real footage: PETS 2009 S2.L1 (shared/data) warped by a known
// sway (the camera turned by up to 3, 2 and 1 degrees of yaw, pitch and roll: K R K^-1, written
// as Motion-JPEG), its NanoDet detections moved alike, tracked with and without
// `--moving-camera` (those whose foot leaves the swayed frame dropped), and NanoDet run on the
// swayed frames themselves. Field positions against the annotations' feet through the PETS
// camera (`eval tracks --camera`; the annotated people the swayed frames show), the swayed runs'
// boxes mapped back to the original frames; the video itself, tracked first in the same process,
// is the baseline (its detections are the ones moved). Prints the median and p90 position error,
// MOTA, the registration's time per frame and how its frames were matched, and the ratios to
// the baseline. About 2.5 min on 2 cores.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/track/camera_motion.h"
#include "fieldvision/track/detection.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/track/pets.h"
#include "fieldvision/track/players.h"
#include "fieldvision/track/position_eval.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace {

namespace fs = std::filesystem;
using fv::track::TrackRow;

const std::string kData = std::string(FV_SHARED_DATA_DIR) + "/pets2009-s2l1";

struct Workspace {
  std::string dir;
  fv::camera::Camera camera;
  std::vector<TrackRow> gt;           // annotated boxes with their feet placed
  std::vector<cv::Matx33d> sway;      // per frame: swayed pixels from the video's
  std::vector<TrackRow> gt_in_view;   // those whose foot the swayed frame still shows
  bool video_run = false;             // BM_Players/video ran in this process (its det.txt)
  std::optional<double> base_median;  // the baseline's, for the ratios
  double base_p90 = 0, base_mota = 0;
};

Workspace& Work() {
  static Workspace w;
  return w;
}

// The camera turned by (yaw, pitch, roll) at frame t; none at frame 0 (the calibrated view).
cv::Matx33d Sway(const fv::camera::Camera& cam, int t) {
  const double a = t == 0 ? 0.0 : 1.0;
  const double deg = M_PI / 180.0;
  cv::Matx33d r;
  cv::Rodrigues(cv::Vec3d(a * 2 * deg * std::sin(2 * M_PI * t / 130.0 + 0.7),
                          a * 3 * deg * std::sin(2 * M_PI * t / 200.0),
                          a * 1 * deg * std::sin(2 * M_PI * t / 90.0 + 1.3)),
                r);
  const cv::Matx33d k(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  return k * r * k.inv();
}

void Prepare() {
  Workspace& w = Work();
  if (!w.dir.empty()) return;
  w.dir = (fs::temp_directory_path() / "fieldvision_bench_moving_camera").string();
  fs::create_directories(w.dir);
  w.camera = fv::track::CameraFromTsai(fv::track::ReadTsaiXml(kData + "/View_001.xml")).camera;
  w.gt = fv::track::ReadPetsCvml(kData + "/PETS2009-S2L1.xml");
  fv::track::PlaceFeet(w.camera, fv::track::TrackerOptions{}.foot_offset_m, &w.gt);
  cv::VideoCapture in(kData + "/vtest.avi");
  FV_REQUIRE(in.isOpened(), "cannot read {}/vtest.avi", kData);
  cv::VideoWriter out(w.dir + "/swayed.avi", cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10,
                      cv::Size(w.camera.width, w.camera.height));
  FV_REQUIRE(out.isOpened(), "cannot write {}/swayed.avi", w.dir);
  cv::Mat frame, swayed;
  for (int t = 0; in.read(frame); ++t) {
    w.sway.push_back(Sway(w.camera, t));
    cv::warpPerspective(frame, swayed, w.sway.back(), frame.size());
    out.write(swayed);
  }
  // Every run is scored on the people the swayed video shows (a detector there sees no others).
  for (const TrackRow& r : w.gt) {
    if (r.frame >= 1 && r.frame <= static_cast<int>(w.sway.size()) &&
        fv::track::FootInView(fv::track::MapBox(w.sway[r.frame - 1], r.box),
                              cv::Size(w.camera.width, w.camera.height))) {
      w.gt_in_view.push_back(r);
    }
  }
}

// The rows' boxes taken back to the original frames (their positions kept).
std::vector<TrackRow> Unswayed(std::vector<TrackRow> rows) {
  for (TrackRow& r : rows) r.box = fv::track::MapBox(Work().sway[r.frame - 1].inv(), r.box);
  return rows;
}

enum class Run { kVideo, kSwayedRegistered, kSwayedAsStill, kSwayedDetected };

void BM_Players(benchmark::State& state, Run run) {
  try {
    Prepare();
  } catch (const fv::Error& e) {
    state.SkipWithError(e.what());
    return;
  }
  Workspace& w = Work();
  fv::track::PlayersOptions o;
  o.progress = false;
  o.detector.min_height_px = 45;  // as bench/players.sh: the annotated area
  std::string video = kData + "/vtest.avi";
  if (run == Run::kVideo) {
    o.detections_out = w.dir + "/det.txt";
  } else if (run == Run::kSwayedDetected) {
    o.moving_camera = true;  // NanoDet on the swayed frames themselves
    video = w.dir + "/swayed.avi";
  } else {
    if (!w.video_run) {
      state.SkipWithError("run BM_Players/video first (its detections are moved)");
      return;
    }
    // The video's detections moved into the swayed frames; those whose foot leaves them dropped.
    fv::track::DetectionsFile det = fv::track::ReadDetectionsCsv(w.dir + "/det.txt");
    for (size_t f = 0; f < det.frames.size(); ++f) {
      std::vector<fv::track::Detection> kept;
      for (auto d : det.frames[f]) {
        d.box = fv::track::MapBox(w.sway[f], d.box);
        if (fv::track::FootInView(d.box, cv::Size(w.camera.width, w.camera.height))) {
          kept.push_back(d);
        }
      }
      det.frames[f] = std::move(kept);
    }
    fv::track::WriteDetectionsCsv(det, w.dir + "/det_swayed.txt");
    o.detections_in = w.dir + "/det_swayed.txt";
    o.moving_camera = run == Run::kSwayedRegistered;
    video = w.dir + "/swayed.avi";
  }
  fv::track::PlayersResult r;
  for (auto _ : state) r = fv::track::RunPlayers(video, &w.camera, nullptr, o);
  const std::vector<TrackRow> est = run == Run::kVideo ? r.rows : Unswayed(r.rows);
  const fv::track::PositionErrors p = fv::track::EvaluatePositions(w.gt_in_view, est);
  const fv::track::MotMetrics m = fv::track::EvaluateMot(w.gt_in_view, est);
  const double median = fv::util::Median(p.errors_m), p90 = fv::util::Percentile(p.errors_m, 0.9);
  state.counters["median_m"] = median;
  state.counters["p90_m"] = p90;
  state.counters["mota"] = m.mota;
  state.counters["register_ms"] = 1000 * r.times.register_s / std::max(1, r.frames);
  if (r.camera_motion) {
    state.counters["direct"] = r.camera_motion->direct;
    state.counters["chained"] = r.camera_motion->chained;
    state.counters["lost"] = r.camera_motion->lost;
  }
  if (run == Run::kVideo) {
    w.video_run = true;
    w.base_median = median;
    w.base_p90 = p90;
    w.base_mota = m.mota;
  } else if (w.base_median && *w.base_median > 0) {
    state.counters["median_x_video"] = median / *w.base_median;
    state.counters["p90_x_video"] = p90 / w.base_p90;
    state.counters["mota_x_video"] = m.mota / w.base_mota;
  }
}

BENCHMARK_CAPTURE(BM_Players, video, Run::kVideo)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_Players, swayed_moving_camera, Run::kSwayedRegistered)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_Players, swayed_as_still, Run::kSwayedAsStill)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_Players, swayed_detected_moving_camera, Run::kSwayedDetected)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
