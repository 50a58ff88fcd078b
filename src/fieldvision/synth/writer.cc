// WriteScene: renders every camera in parallel and writes videos, camera files and truth.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/codecs/codecs.h"
#include "fieldvision/synth/figures.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"

namespace fv::synth {
namespace fs = std::filesystem;

namespace {

// The quality to give OpenCV's MJPG writer (cv::CAP_OPENCV_MJPEG) for frames quantised as
// libjpeg (cv::imwrite) quantises at `jpeg_quality`: libjpeg scales the standard tables by s %
// (s = 5000 / q below 50, else 200 - 2 q), that writer divides them by 0.12 x its own quality,
// clamped to 1..12 (so its 90 is about libjpeg's 95). It reaches libjpeg's 50..95, which
// SceneSpec::Check requires for "avi".
double MjpegWriterQuality(int jpeg_quality) {
  FV_REQUIRE(jpeg_quality >= 1 && jpeg_quality <= 100, "JPEG quality {} is not in 1..100",
             jpeg_quality);
  const double percent = jpeg_quality < 50 ? 5000.0 / jpeg_quality : 200.0 - 2.0 * jpeg_quality;
  return 100.0 / (0.12 * std::max(percent, 1.0));
}

}  // namespace

std::string WriteSceneResult::Summary() const {
  // One camera (the players scene) triangulates nothing: no count of the ball's 3D frames.
  return fmt::format(
      "{} camera{} x {} frames in {:.1f} s ({:.1f} frames/s over all cameras; set-up {:.1f} s); "
      "{}{} files in {}",
      num_cameras, num_cameras == 1 ? "" : "s", num_frames, seconds,
      seconds > 0 ? num_cameras * num_frames / seconds : 0.0, setup_seconds,
      num_cameras >= 2
          ? fmt::format("ball seen by >= 2 cameras in {} frames; ", frames_with_ball_in_2plus_cams)
          : "",
      files.size(), out_dir);
}

cv::Mat ContactSheet(const std::vector<cv::Mat>& images, const std::vector<std::string>& names,
                     int tile_width) {
  FV_REQUIRE(!images.empty(), "contact sheet: no images");
  FV_REQUIRE(tile_width > 0, "contact sheet: tile width must be > 0");
  const int n = static_cast<int>(images.size());
  const int cols = n <= 1 ? 1 : (n <= 4 ? 2 : 3);
  const int rows = (n + cols - 1) / cols;
  int tile_h = 0;
  std::vector<cv::Mat> tiles;
  for (const cv::Mat& im : images) {
    cv::Mat t;
    const int th =
        std::max(1, static_cast<int>(std::lround(im.rows * tile_width / double(im.cols))));
    cv::resize(im, t, cv::Size(tile_width, th), 0, 0, cv::INTER_AREA);
    tile_h = std::max(tile_h, th);
    tiles.push_back(t);
  }
  const int gap = 4;
  cv::Mat sheet(rows * tile_h + (rows + 1) * gap, cols * tile_width + (cols + 1) * gap, CV_8UC3,
                cv::Scalar(30, 30, 30));
  for (int i = 0; i < n; ++i) {
    const int r = i / cols, c = i % cols;
    const cv::Rect roi(gap + c * (tile_width + gap), gap + r * (tile_h + gap), tile_width,
                       tiles[i].rows);
    tiles[i].copyTo(sheet(roi));
    const std::string label = i < static_cast<int>(names.size()) ? names[i] : fmt::format("{}", i);
    int base = 0;
    const cv::Size ts = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, 0.7, 2, &base);
    cv::rectangle(sheet, cv::Rect(roi.x, roi.y, ts.width + 12, ts.height + base + 10),
                  cv::Scalar(0, 0, 0), cv::FILLED);
    cv::putText(sheet, label, cv::Point(roi.x + 6, roi.y + ts.height + 5), cv::FONT_HERSHEY_SIMPLEX,
                0.7, cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
  }
  return sheet;
}

namespace {

// Output paths of a scene folder.
struct SceneFolder {
  std::string dir;
  std::string Path(const std::string& name) const { return (fs::path(dir) / name).string(); }
};

// scene.json (the spec as given) and one camera file per camera.
void WriteSpecAndCameras(const SceneSpec& spec, const SceneRenderer& scene,
                         const SceneFolder& folder, WriteSceneResult& res) {
  const std::string p = folder.Path("scene.json");
  std::ofstream out(p);
  FV_REQUIRE(out.good(), "cannot write '{}'", p);
  out << SceneSpecToJson(spec).dump(2) << "\n";
  FV_REQUIRE(out.good(), "cannot write '{}'", p);
  res.files.push_back(p);
  for (const camera::Camera& cam : scene.cameras()) {
    const std::string yaml = folder.Path(cam.name + ".yaml");
    camera::WriteCameraYaml(cam, yaml);
    res.files.push_back(yaml);
  }
}

// Per camera: the video file or image pattern, created folders and an open video writer.
struct CameraOut {
  std::string file;
  std::mutex mutex;
  std::unique_ptr<cv::VideoWriter> writer;
  std::map<int, cv::Mat> pending;
  int next_write = 0;
};

std::vector<std::unique_ptr<CameraOut>> OpenOutputs(const SceneSpec& spec,
                                                    const SceneRenderer& scene,
                                                    const SceneFolder& folder) {
  std::vector<std::unique_ptr<CameraOut>> outs;
  for (const camera::Camera& cam : scene.cameras()) {
    outs.push_back(std::make_unique<CameraOut>());
    CameraOut& out = *outs.back();
    if (spec.format == "mp4") {
      out.file = folder.Path(cam.name + ".mp4");
      out.writer = codecs::NewVideoWriter();
      FV_REQUIRE(codecs::OpenVideoWriter(out.writer.get(), out.file, cv::CAP_FFMPEG,
                                         codecs::FourCc('a', 'v', 'c', '1'), spec.fps,
                                         cv::Size(cam.width, cam.height)),
                 "cannot open H.264 video '{}' for writing (OpenCV's FFmpeg has no H.264 encoder "
                 "here? format \"avi\" writes Motion-JPEG)",
                 out.file);
      continue;
    }
    if (spec.format != "avi") {
      std::error_code ec;
      fs::create_directories(folder.Path(cam.name), ec);
      FV_REQUIRE(!ec, "cannot create folder '{}'", folder.Path(cam.name));
      out.file = folder.Path(cam.name + "/%05d." + spec.format);
      continue;
    }
    out.file = folder.Path(cam.name + ".avi");
    out.writer = codecs::NewVideoWriter();
    codecs::OpenVideoWriter(out.writer.get(), out.file, cv::CAP_OPENCV_MJPEG,
                            codecs::FourCc('M', 'J', 'P', 'G'), spec.fps,
                            cv::Size(cam.width, cam.height));
    FV_REQUIRE(out.writer->isOpened(), "cannot open video '{}' for writing", out.file);
    out.writer->set(cv::VIDEOWRITER_PROP_QUALITY, MjpegWriterQuality(spec.jpeg_quality));
  }
  return outs;
}

// Renders every (frame, camera) in frame-major order on a pool of threads; each camera's frames
// are written in order as soon as they are ready. Fills stats[camera][frame] and first[camera].
void RenderAndWrite(const SceneSpec& spec, const SceneRenderer& scene, const SceneFolder& folder,
                    std::vector<std::unique_ptr<CameraOut>>& outs,
                    std::vector<std::vector<CameraFrameStats>>& stats, std::vector<cv::Mat>& first,
                    bool progress) {
  const int nc = static_cast<int>(outs.size()), nf = spec.num_frames;
  const std::vector<int> params =
      spec.format == "jpg" ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, spec.jpeg_quality}
                           : std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, 1};
  const long long total = static_cast<long long>(nc) * nf;
  std::atomic<long long> done{0};
  std::atomic<long long> next{0};
  std::mutex error_mutex;
  std::string error;
  auto write_ready = [&](CameraOut& out, int c) {
    while (!out.pending.empty() && out.pending.begin()->first == out.next_write) {
      if (out.writer) {
        out.writer->write(out.pending.begin()->second);
      } else {
        const std::string p = fmt::format("{}/{}/{:05d}.{}", folder.dir, scene.cameras()[c].name,
                                          out.next_write, spec.format);
        FV_REQUIRE(codecs::ImWrite(p, out.pending.begin()->second, params),
                   "cannot write image '{}'", p);
      }
      out.pending.erase(out.pending.begin());
      ++out.next_write;
      ++done;
    }
  };
  auto worker = [&] {
    for (long long i = next++; i < total; i = next++) {
      const int f = static_cast<int>(i / nc), c = static_cast<int>(i % nc);
      try {
        cv::Mat img = scene.RenderCamera(c, f, &stats[c][f]);
        if (f == 0) first[c] = img.clone();
        CameraOut& out = *outs[c];
        std::lock_guard<std::mutex> lock(out.mutex);
        out.pending.emplace(f, std::move(img));
        write_ready(out, c);
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (error.empty()) error = e.what();
        next = total;
      }
    }
  };
  util::Progress prog("synth: rendering", total, "frames", progress);
  const int n_threads = static_cast<int>(
      std::min<long long>(total, std::max(1u, std::thread::hardware_concurrency())));
  std::vector<std::thread> threads;
  threads.reserve(n_threads);
  for (int k = 0; k < n_threads; ++k) threads.emplace_back(worker);
  while (true) {
    bool all_done = done.load() >= total;
    {
      std::lock_guard<std::mutex> lock(error_mutex);
      all_done = all_done || !error.empty();
    }
    prog.Update(done.load());
    if (all_done) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  for (auto& t : threads) t.join();
  for (auto& o : outs) {
    if (o->writer) o->writer->release();
  }
  prog.Update(done.load());
  prog.Finish();
  FV_REQUIRE(error.empty(), "{}", error);
}

// truth.csv (centre, cameras that see it) and truth_2d.csv (per camera in front of the ball).
void WriteBallTruth(const SceneSpec& spec, const SceneRenderer& scene, const SceneFolder& folder,
                    const std::vector<std::vector<CameraFrameStats>>& stats,
                    WriteSceneResult& res) {
  const int nc = res.num_cameras, nf = spec.num_frames;
  util::CsvWriter truth(folder.Path("truth.csv"),
                        {"frame", "time_s", "x_m", "y_m", "z_m", "n_cams"}, 6);
  util::CsvWriter truth2d(folder.Path("truth_2d.csv"),
                          {"frame", "cam", "u_px", "v_px", "radius_px", "visible_fraction"}, 4);
  if (spec.ball.enabled) {
    for (int f = 0; f < nf; ++f) {
      const Eigen::Vector3d c = scene.BallAt(scene.FrameTime(f));
      int n_cams = 0;
      for (int k = 0; k < nc; ++k) {
        const BallCameraTruth& b = stats[k][f].ball;
        if (b.in_front && b.visible_fraction >= 0.3) ++n_cams;
        if (!b.in_front) continue;
        truth2d << f << scene.cameras()[k].name << b.uv_px.x() << b.uv_px.y() << b.radius_px
                << b.visible_fraction;
        truth2d.EndRow();
      }
      if (n_cams >= 2) ++res.frames_with_ball_in_2plus_cams;
      truth << f << scene.FrameTime(f) << c.x() << c.y() << c.z() << n_cams;
      truth.EndRow();
    }
  }
  truth.Close();
  truth2d.Close();
  res.files.push_back(folder.Path("truth.csv"));
  res.files.push_back(folder.Path("truth_2d.csv"));
}

// players.csv (positions from the paths the renderer used) and players_2d.csv (image boxes).
void WritePlayerTruth(const SceneSpec& spec, const SceneRenderer& scene, const SceneFolder& folder,
                      const std::vector<std::vector<CameraFrameStats>>& stats,
                      WriteSceneResult& res) {
  const int nc = res.num_cameras, nf = spec.num_frames;
  util::CsvWriter players(folder.Path("players.csv"),
                          {"frame", "time_s", "id", "team", "x_m", "y_m"}, 4);
  util::CsvWriter players2d(
      folder.Path("players_2d.csv"),
      {"frame", "cam", "id", "bb_left", "bb_top", "bb_width", "bb_height", "visible_fraction"}, 4);
  for (int f = 0; f < nf; ++f) {
    const double t = scene.FrameTime(f);
    for (size_t i = 0; i < spec.people.size(); ++i) {
      const PersonSpec& p = spec.people[i];
      const Eigen::Vector2d xy = PathAt(p.path, t).position_m;
      players << f << t << p.id << p.team << xy.x() << xy.y();
      players.EndRow();
      for (int k = 0; k < nc; ++k) {
        const PlayerCameraTruth& pc = stats[k][f].players[i];
        if (!pc.in_image) continue;
        players2d << f << scene.cameras()[k].name << p.id << pc.bb_left << pc.bb_top << pc.bb_width
                  << pc.bb_height << pc.visible_fraction;
        players2d.EndRow();
      }
    }
  }
  players.Close();
  players2d.Close();
  res.files.push_back(folder.Path("players.csv"));
  res.files.push_back(folder.Path("players_2d.csv"));
}

}  // namespace

WriteSceneResult WriteScene(const SceneSpec& spec, const std::string& out_dir, bool progress) {
  const auto t0 = std::chrono::steady_clock::now();
  spec.Check();
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  FV_REQUIRE(!ec && fs::is_directory(out_dir), "cannot create output folder '{}'", out_dir);
  WriteSceneResult res;
  res.out_dir = out_dir;
  res.num_frames = spec.num_frames;
  res.num_cameras = static_cast<int>(spec.cameras.size());
  const SceneRenderer scene(spec);
  res.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const SceneFolder folder{out_dir};
  WriteSpecAndCameras(spec, scene, folder, res);

  const int nc = res.num_cameras, nf = spec.num_frames;
  std::vector<std::vector<CameraFrameStats>> stats(nc, std::vector<CameraFrameStats>(nf));
  std::vector<cv::Mat> first(nc);
  auto outs = OpenOutputs(spec, scene, folder);
  RenderAndWrite(spec, scene, folder, outs, stats, first, progress);
  for (const auto& o : outs) res.files.push_back(o->file);

  WriteBallTruth(spec, scene, folder, stats, res);
  {
    const std::string p = folder.Path("flights.json");
    std::ofstream out(p);
    FV_REQUIRE(out.good(), "cannot write '{}'", p);
    out << FlightsToJson(scene.Flights()).dump(2) << "\n";
    res.files.push_back(p);
  }
  if (!spec.people.empty()) WritePlayerTruth(spec, scene, folder, stats, res);
  std::vector<std::string> names;
  for (const camera::Camera& c : scene.cameras()) {
    names.push_back(fmt::format("{}  {}x{}  frame 0", c.name, c.width, c.height));
  }
  const cv::Mat sheet = ContactSheet(first, names, first.size() > 1 ? 640 : 960);
  const std::string p = folder.Path("contact_sheet.png");
  FV_REQUIRE(codecs::ImWrite(p, sheet), "cannot write '{}'", p);
  res.files.push_back(p);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace fv::synth
