// Players with a moving camera on real footage: PETS 2009 S2.L1 (shared/data) warped by a known
// motion, its NanoDet detections moved alike. (1) A sway: the camera turned by up to 3, 2 and 1
// degrees of yaw, pitch and roll (K R K^-1), tracked with and without `--moving-camera` (those
// whose foot leaves the swayed frame dropped), and NanoDet run on the swayed frames themselves.
// (2) A pan: a pinhole camera with 1.6 times the focal length at the PETS camera's centre, its
// aim swept left and right (yaw up to a fifth of the image width each way) so that people walk in
// and out of a view that never shows the whole scene (rendered through the PETS lens with
// cv::initUndistortRectifyMap), tracked with `--moving-camera` on its canvas and with no canvas
// beyond the first view (`--canvas-margin 0`). Written as Motion-JPEG. Field positions against
// the annotations' feet through the PETS camera (`eval tracks --camera`; the annotated people the
// moved frames show), the moved runs' boxes mapped back to the original frames; the video itself,
// tracked first in the same process, is the baseline (its detections are the ones moved). Prints
// the median and p90 position error, the share of the annotated people shown that are matched
// with a position, MOTA, the registration's time per frame and how its frames were matched, and
// the ratios to the baseline. About 3.5 min on 2 cores.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/camera/opencv_camera.h"
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

// A moved video: how each frame's pixels relate to the original's.
struct Moved {
  std::string video;
  // Frame t's (0-based) pixel from the original's and back; nullopt where it does not map.
  std::function<std::optional<cv::Point2d>(int, const cv::Point2d&)> from_original, to_original;
  std::vector<TrackRow> gt_in_view;  // the annotated people whose foot the moved frames show
  fv::camera::Camera camera;         // the camera file of the moved video (its first view)
};

struct Workspace {
  std::string dir;
  fv::camera::Camera camera;
  std::vector<TrackRow> gt;       // annotated boxes with their feet placed
  std::vector<cv::Matx33d> sway;  // per frame: swayed pixels from the video's
  std::vector<cv::Matx33d> pan;   // per frame: the pan camera's turn from the PETS camera
  fv::camera::Camera pan_camera;  // the pan camera unturned (intrinsics; no pose)
  Moved swayed, panned;
  // BM_Players/video's tracks, once it ran in this process (its det.txt is the one moved).
  std::optional<std::vector<TrackRow>> video_rows;
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
  return fv::camera::IntrinsicMatrix(cam) * r * fv::camera::IntrinsicMatrix(cam).inv();
}

constexpr double kPanZoom = 1.6;

// The pan camera's turn from the PETS camera at frame t: a yaw moving its aim by up to a fifth of
// the image width each way (a sweep of 400 frames), a slight pitch; none at frame 0.
cv::Matx33d PanTurn(const fv::camera::Camera& cam, int t) {
  const double yaw = std::atan(0.2 * cam.width / cam.fx), pitch = M_PI / 360.0;
  cv::Matx33d q;
  cv::Rodrigues(
      cv::Vec3d(pitch * std::sin(2 * M_PI * t / 150.0), yaw * std::sin(2 * M_PI * t / 400.0), 0.0),
      q);
  return q;
}

// Writes the moved video and keeps the annotated people its frames show.
void WriteMoved(const std::string& name,
                const std::function<void(int, const cv::Mat&, cv::Mat&)>& render, Moved& moved) {
  Workspace& w = Work();
  moved.video = w.dir + "/" + name + ".avi";
  cv::VideoCapture in(kData + "/vtest.avi");
  FV_REQUIRE(in.isOpened(), "cannot read {}/vtest.avi", kData);
  const cv::Size size(w.camera.width, w.camera.height);
  cv::VideoWriter out(moved.video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, size);
  FV_REQUIRE(out.isOpened(), "cannot write {}", moved.video);
  cv::Mat frame, view;
  int frames = 0;
  for (; in.read(frame); ++frames) {
    render(frames, frame, view);
    out.write(view);
  }
  // Every run is scored on the people the moved video shows (a detector there sees no others).
  for (const TrackRow& r : w.gt) {
    if (r.frame < 1 || r.frame > frames) continue;
    const cv::Rect2d box = fv::track::MapBoxBy(
        [&](const cv::Point2d& p) { return moved.from_original(r.frame - 1, p); }, r.box);
    if (fv::track::FootInView(box, size)) moved.gt_in_view.push_back(r);
  }
}

void PrepareSway() {
  Workspace& w = Work();
  for (int t = 0; t < 795; ++t) w.sway.push_back(Sway(w.camera, t));
  Moved& m = w.swayed;
  m.camera = w.camera;
  m.from_original = [&w](int t, const cv::Point2d& p) {
    return std::optional(fv::track::MapPoint(w.sway[t], p));
  };
  m.to_original = [&w](int t, const cv::Point2d& p) {
    return std::optional(fv::track::MapPoint(w.sway[t].inv(), p));
  };
  WriteMoved(
      "swayed",
      [&w](int t, const cv::Mat& f, cv::Mat& v) {
        cv::warpPerspective(f, v, w.sway.at(t), f.size());
      },
      m);
}

void PreparePan() {
  Workspace& w = Work();
  fv::camera::Camera& pin = w.pan_camera;
  pin = w.camera;
  pin.fx *= kPanZoom;
  pin.fy *= kPanZoom;
  pin.distortion.clear();
  for (int t = 0; t < 795; ++t) w.pan.push_back(PanTurn(w.camera, t));
  Moved& m = w.panned;
  m.camera = pin;  // the first view: PanTurn(0) is no turn
  m.from_original = [&w](int t, const cv::Point2d& p) -> std::optional<cv::Point2d> {
    const auto n = w.camera.Undistort({p.x, p.y});
    if (!n) return std::nullopt;
    const cv::Vec3d v =
        fv::camera::IntrinsicMatrix(w.pan_camera) * (w.pan[t] * cv::Vec3d(n->x(), n->y(), 1.0));
    if (!(v[2] > 0)) return std::nullopt;
    return cv::Point2d(v[0] / v[2], v[1] / v[2]);
  };
  m.to_original = [&w](int t, const cv::Point2d& p) -> std::optional<cv::Point2d> {
    const cv::Vec3d v =
        w.pan[t].t() * (fv::camera::IntrinsicMatrix(w.pan_camera).inv() * cv::Vec3d(p.x, p.y, 1));
    const auto uv = w.camera.ProjectFromCamera({v[0], v[1], v[2]});
    if (!uv) return std::nullopt;
    return cv::Point2d(uv->x(), uv->y());
  };
  WriteMoved(
      "panned",
      [&w](int t, const cv::Mat& f, cv::Mat& v) {
        cv::Mat map1, map2;
        cv::initUndistortRectifyMap(
            fv::camera::IntrinsicMatrix(w.camera), fv::camera::DistortionRow(w.camera), w.pan.at(t),
            fv::camera::IntrinsicMatrix(w.pan_camera), f.size(), CV_16SC2, map1, map2);
        cv::remap(f, v, map1, map2, cv::INTER_LINEAR);
      },
      m);
}

void Prepare() {
  Workspace& w = Work();
  if (!w.dir.empty()) return;
  w.dir = (fs::temp_directory_path() / "fieldvision_bench_moving_camera").string();
  fs::create_directories(w.dir);
  w.camera = fv::track::CameraFromTsai(fv::track::ReadTsaiXml(kData + "/View_001.xml")).camera;
  w.gt = fv::track::ReadPetsCvml(kData + "/PETS2009-S2L1.xml");
  fv::track::PlaceFeet(w.camera, fv::track::TrackerOptions{}.foot_offset_m, &w.gt);
  PrepareSway();
  PreparePan();
}

// Rows moved by a point mapping per frame (their positions kept).
std::vector<TrackRow> MoveRows(
    std::vector<TrackRow> rows,
    const std::function<std::optional<cv::Point2d>(int, const cv::Point2d&)>& to) {
  for (TrackRow& r : rows) {
    r.box = fv::track::MapBoxBy([&](const cv::Point2d& p) { return to(r.frame - 1, p); }, r.box);
  }
  return rows;
}

// The video's detections moved into the moved frames (those whose foot leaves them dropped).
std::string MoveDetections(const Moved& m, const std::string& name) {
  Workspace& w = Work();
  fv::track::DetectionsFile det = fv::track::ReadDetectionsCsv(w.dir + "/det.txt");
  for (size_t f = 0; f < det.frames.size(); ++f) {
    std::vector<fv::track::Detection> kept;
    for (auto d : det.frames[f]) {
      d.box = fv::track::MapBoxBy(
          [&](const cv::Point2d& p) { return m.from_original(static_cast<int>(f), p); }, d.box);
      if (fv::track::FootInView(d.box, cv::Size(w.camera.width, w.camera.height))) {
        kept.push_back(d);
      }
    }
    det.frames[f] = std::move(kept);
  }
  const std::string path = w.dir + "/det_" + name + ".txt";
  fv::track::WriteDetectionsCsv(det, path);
  return path;
}

enum class Run {
  kVideo,
  kSwayedRegistered,
  kSwayedAsStill,
  kSwayedDetected,
  kPannedRegistered,
  kPannedFirstViewOnly
};

struct Score {
  double median = 0, p90 = 0, mota = 0, matched = 0;
};

Score ScoreRows(const std::vector<TrackRow>& gt, const std::vector<TrackRow>& est) {
  const fv::track::PositionErrors p = fv::track::EvaluatePositions(gt, est);
  return {fv::util::Median(p.errors_m), fv::util::Percentile(p.errors_m, 0.9),
          fv::track::EvaluateMot(gt, est).mota,
          static_cast<double>(p.errors_m.size()) / std::max(1, p.gt_boxes)};
}

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
  const bool panned = run == Run::kPannedRegistered || run == Run::kPannedFirstViewOnly;
  const Moved* moved = panned ? &w.panned : &w.swayed;
  std::string video = kData + "/vtest.avi";
  const fv::camera::Camera* camera = run == Run::kVideo ? &w.camera : &moved->camera;
  if (run == Run::kVideo) {
    o.detections_out = w.dir + "/det.txt";
  } else if (run == Run::kSwayedDetected) {
    o.moving_camera = true;  // NanoDet on the swayed frames themselves
    video = moved->video;
  } else {
    if (!w.video_rows) {
      state.SkipWithError("run BM_Players/video first (its detections are moved)");
      return;
    }
    o.detections_in = MoveDetections(*moved, panned ? "panned" : "swayed");
    o.moving_camera = run != Run::kSwayedAsStill;
    if (run == Run::kPannedFirstViewOnly) o.camera_motion.canvas_margin = 0;
    video = moved->video;
  }
  fv::track::PlayersResult r;
  for (auto _ : state) r = fv::track::RunPlayers(video, camera, nullptr, o);
  const std::vector<TrackRow> est =
      run == Run::kVideo ? r.rows : MoveRows(r.rows, moved->to_original);
  const std::vector<TrackRow>& gt = run == Run::kVideo ? w.gt : moved->gt_in_view;
  const Score score = ScoreRows(gt, est);
  state.counters["median_m"] = score.median;
  state.counters["p90_m"] = score.p90;
  state.counters["mota"] = score.mota;
  state.counters["matched"] = score.matched;
  state.counters["register_ms"] = 1000 * r.times.register_s / std::max(1, r.frames);
  if (r.camera_motion) {
    state.counters["direct"] = r.camera_motion->direct;
    state.counters["keyed"] = r.camera_motion->keyed;
    state.counters["chained"] = r.camera_motion->chained;
    state.counters["lost"] = r.camera_motion->lost;
  }
  if (run == Run::kVideo) {
    w.video_rows = r.rows;
    return;
  }
  if (!w.video_rows) return;  // no baseline to compare with (BM_Players/video did not run)
  // The baseline: the video's own tracks of the people the moved frames show.
  std::vector<TrackRow> shown;
  for (const TrackRow& row : *w.video_rows) {
    const cv::Rect2d box = fv::track::MapBoxBy(
        [&](const cv::Point2d& p) { return moved->from_original(row.frame - 1, p); }, row.box);
    if (fv::track::FootInView(box, cv::Size(w.camera.width, w.camera.height))) {
      shown.push_back(row);
    }
  }
  const Score base = ScoreRows(gt, shown);
  state.counters["video_median_m"] = base.median;
  if (base.median > 0) state.counters["median_x_video"] = score.median / base.median;
  if (base.p90 > 0) state.counters["p90_x_video"] = score.p90 / base.p90;
  if (base.mota > 0) state.counters["mota_x_video"] = score.mota / base.mota;
  if (base.matched > 0) state.counters["matched_x_video"] = score.matched / base.matched;
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
BENCHMARK_CAPTURE(BM_Players, panned_moving_camera, Run::kPannedRegistered)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_Players, panned_first_view_only, Run::kPannedFirstViewOnly)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
