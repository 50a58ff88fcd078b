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
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/synth/figures.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"

namespace fv::synth {
namespace fs = std::filesystem;

std::string WriteSceneResult::Summary() const {
  return fmt::format(
      "{} cameras x {} frames in {:.1f} s ({:.1f} frames/s over all cameras; set-up {:.1f} s); "
      "ball seen by >= 2 cameras in {} frames; {} files in {}",
      num_cameras, num_frames, seconds, seconds > 0 ? num_cameras * num_frames / seconds : 0.0,
      setup_seconds, frames_with_ball_in_2plus_cams, files.size(), out_dir);
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
  auto path = [&](const std::string& name) { return (fs::path(out_dir) / name).string(); };

  {
    const std::string p = path("scene.json");
    std::ofstream out(p);
    FV_REQUIRE(out.good(), "cannot write '{}'", p);
    out << SceneSpecToJson(spec).dump(2) << "\n";
    FV_REQUIRE(out.good(), "cannot write '{}'", p);
    res.files.push_back(p);
  }
  for (const Camera& cam : scene.cameras()) {
    const std::string p = path(cam.name + ".yaml");
    WriteCameraYaml(cam, p);
    res.files.push_back(p);
  }

  const int nc = res.num_cameras, nf = spec.num_frames;
  std::vector<std::vector<CameraFrameStats>> stats(nc, std::vector<CameraFrameStats>(nf));
  std::vector<cv::Mat> first(nc);
  std::vector<std::string> video_files(nc);
  for (int c = 0; c < nc; ++c) {
    const std::string& name = scene.cameras()[c].name;
    if (spec.format == "avi") {
      video_files[c] = path(name + ".avi");
    } else {
      fs::create_directories(path(name), ec);
      FV_REQUIRE(!ec, "cannot create folder '{}'", path(name));
      video_files[c] = path(name + "/%05d." + spec.format);
    }
  }
  // Work items are (frame, camera) in frame-major order, rendered by a pool of threads; each
  // camera's frames are written in order as soon as they are ready.
  struct CameraOut {
    std::mutex mutex;
    cv::VideoWriter writer;
    std::map<int, cv::Mat> pending;
    int next_write = 0;
  };
  std::vector<std::unique_ptr<CameraOut>> outs;
  for (int c = 0; c < nc; ++c) {
    outs.push_back(std::make_unique<CameraOut>());
    if (spec.format != "avi") continue;
    const Camera& cam = scene.cameras()[c];
    cv::VideoWriter& writer = outs.back()->writer;
    writer.open(video_files[c], cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                spec.fps, cv::Size(cam.width, cam.height), true);
    FV_REQUIRE(writer.isOpened(), "cannot open video '{}' for writing", video_files[c]);
    writer.set(cv::VIDEOWRITER_PROP_QUALITY, spec.jpeg_quality);
  }
  const std::vector<int> params =
      spec.format == "jpg" ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, spec.jpeg_quality}
                           : std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, 1};
  const long long total = static_cast<long long>(nc) * nf;
  std::atomic<long long> done{0};
  std::atomic<long long> next{0};
  std::mutex error_mutex;
  std::string error;
  auto worker = [&] {
    for (long long i = next++; i < total; i = next++) {
      const int f = static_cast<int>(i / nc), c = static_cast<int>(i % nc);
      try {
        cv::Mat img = scene.RenderCamera(c, f, &stats[c][f]);
        if (f == 0) first[c] = img.clone();
        CameraOut& out = *outs[c];
        std::lock_guard<std::mutex> lock(out.mutex);
        out.pending.emplace(f, std::move(img));
        while (!out.pending.empty() && out.pending.begin()->first == out.next_write) {
          if (spec.format == "avi") {
            out.writer.write(out.pending.begin()->second);
          } else {
            const std::string p = fmt::format("{}/{}/{:05d}.{}", out_dir, scene.cameras()[c].name,
                                              out.next_write, spec.format);
            FV_REQUIRE(cv::imwrite(p, out.pending.begin()->second, params),
                       "cannot write image '{}'", p);
          }
          out.pending.erase(out.pending.begin());
          ++out.next_write;
          ++done;
        }
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (error.empty()) error = e.what();
        next = total;
      }
    }
  };
  {
    Progress prog("synth: rendering", static_cast<long long>(nc) * nf, "frames", progress);
    const int n_threads = static_cast<int>(
        std::min<long long>(total, std::max(1u, std::thread::hardware_concurrency())));
    std::vector<std::thread> threads;
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
    for (auto& o : outs) o->writer.release();
    prog.Update(done.load());
    prog.Finish();
  }
  FV_REQUIRE(error.empty(), "{}", error);
  for (int c = 0; c < nc; ++c) res.files.push_back(video_files[c]);

  // Ball truth.
  {
    CsvWriter truth(path("truth.csv"), {"frame", "time_s", "x_m", "y_m", "z_m", "n_cams"}, 6);
    CsvWriter truth2d(path("truth_2d.csv"),
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
    res.files.push_back(path("truth.csv"));
    res.files.push_back(path("truth_2d.csv"));
  }
  {
    const std::string p = path("flights.json");
    std::ofstream out(p);
    FV_REQUIRE(out.good(), "cannot write '{}'", p);
    out << FlightsToJson(scene.Flights()).dump(2) << "\n";
    res.files.push_back(p);
  }
  if (!spec.people.empty()) {
    CsvWriter players(path("players.csv"), {"frame", "time_s", "id", "team", "x_m", "y_m"}, 4);
    CsvWriter players2d(
        path("players_2d.csv"),
        {"frame", "cam", "id", "bb_left", "bb_top", "bb_width", "bb_height", "visible_fraction"},
        4);
    // Positions from the paths the renderer used; boxes from the rendering.
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
          players2d << f << scene.cameras()[k].name << p.id << pc.bb_left << pc.bb_top
                    << pc.bb_width << pc.bb_height << pc.visible_fraction;
          players2d.EndRow();
        }
      }
    }
    players.Close();
    players2d.Close();
    res.files.push_back(path("players.csv"));
    res.files.push_back(path("players_2d.csv"));
  }
  {
    std::vector<std::string> names;
    for (const Camera& c : scene.cameras()) {
      names.push_back(fmt::format("{}  {}x{}  frame 0", c.name, c.width, c.height));
    }
    const cv::Mat sheet = ContactSheet(first, names, first.size() > 1 ? 640 : 960);
    const std::string p = path("contact_sheet.png");
    FV_REQUIRE(cv::imwrite(p, sheet), "cannot write '{}'", p);
    res.files.push_back(p);
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace fv::synth
