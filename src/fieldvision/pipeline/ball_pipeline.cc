#include "fieldvision/pipeline/ball_pipeline.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "fieldvision/pipeline/jpeg_region.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"

namespace fv {

void BallPipelineOptions::Check() const {
  sync.Check();
  FV_REQUIRE(queue_capacity >= 1 && queue_capacity <= 10000,
             "BallPipelineOptions.queue_capacity must be in [1, 10000] (got {})", queue_capacity);
  FV_REQUIRE(max_frames >= 0, "BallPipelineOptions.max_frames must be >= 0 (got {})", max_frames);
  triangulation.Check();
  track.Check();
}

std::string BallPipelineSummary::ToString() const {
  std::string s = fmt::format(
      "{} synchronised frames, {} with a ball position ({:.1f} %){}, mean reprojection error "
      "{:.2f} px\n",
      frames, frames_with_position, frames ? 100.0 * frames_with_position / frames : 0.0,
      ground_positions
          ? fmt::format(" of which {} single-camera ground positions", ground_positions)
          : "",
      mean_err_px);
  if (weak_positions > 0) {
    s += fmt::format(
        "{} positions completed with weak candidates (failed a shape check in one "
        "camera, consistent with the others)\n",
        weak_positions);
  }
  if (frames > frames_with_position) {
    s += fmt::format(
        "no position: {} frames with candidates in fewer than 2 cameras, {} frames "
        "whose candidates disagree\n",
        frames_few_blobs, frames_inconsistent);
  }
  s += "cameras used:";
  for (int c = 0; c < num_cameras; ++c) {
    const std::string name =
        c < static_cast<int>(camera_names.size()) ? camera_names[c] : fmt::format("camera {}", c);
    s += fmt::format(" {} {} ({} candidates)", name, used_per_camera[c], candidates_per_camera[c]);
    if (queue_drops[c] > 0) s += fmt::format(" [{} dropped by the queue]", queue_drops[c]);
    s += c + 1 < num_cameras ? "," : "";
  }
  s += fmt::format("\n{:.2f} s, {:.1f} frames/s", seconds, fps);
  long long full = 0, window = 0;
  for (long long f : full_scans) full += f;
  for (long long w : window_scans) window += w;
  if (window > 0) {
    s += fmt::format(", {} camera frames searched in a window around the ball, {} whole", window,
                     full);
  }
  for (const std::string& p : sync.Problems()) s += "\nsync: " + p;
  for (int c = 0; c < num_cameras && c < static_cast<int>(bad_frames.size()); ++c) {
    if (bad_frames[c] > 0) {
      s += fmt::format("\n{}: {} frames could not be decoded (first: {})", camera_names[c],
                       bad_frames[c], first_bad_frame[c]);
    }
  }
  return s;
}

namespace {

// At least one candidate that is not weak.
bool HasAccepted(const std::vector<BallObservation>& obs) {
  return std::any_of(obs.begin(), obs.end(), [](const BallObservation& o) { return !o.weak; });
}

}  // namespace

void BallPredictor::Add(long long frame, const Eigen::Vector3d& point_world) {
  frame_[1] = frame_[0];
  point_[1] = point_[0];
  frame_[0] = frame;
  point_[0] = point_world;
  count_ = std::min(count_ + 1, 2);
}

std::optional<Eigen::Vector3d> BallPredictor::Predict(long long frame) const {
  if (count_ == 0 || frame - frame_[0] > max_gap_ || frame < frame_[0]) return std::nullopt;
  if (count_ < 2 || frame_[0] - frame_[1] > max_gap_ || frame_[0] <= frame_[1]) return point_[0];
  const Eigen::Vector3d v = (point_[0] - point_[1]) / double(frame_[0] - frame_[1]);
  return point_[0] + v * double(frame - frame_[0]);
}

BallFrame FuseFrame(const std::vector<Camera>& cameras, const SyncedFrame& frame,
                    const TriangulationOptions& options, const Eigen::Vector3d* prior) {
  BallFrame out;
  out.frame = frame.frame;
  out.time_s = frame.time_s;
  std::vector<std::vector<BallObservation>> candidates(cameras.size());
  for (size_t c = 0; c < cameras.size() && c < frame.cameras.size(); ++c) {
    if (!frame.cameras[c]) continue;
    ++out.cameras_present;
    candidates[c] = frame.cameras[c]->candidates;
    if (HasAccepted(candidates[c])) ++out.cameras_with_blobs;
  }
  out.result = TriangulateRobust(cameras, candidates, options, prior);
  return out;
}

void BallTrackOptions::Check() const {
  FV_REQUIRE(full_scan_every >= 1, "BallTrackOptions.full_scan_every must be >= 1 (got {})",
             full_scan_every);
  FV_REQUIRE(std::isfinite(window_radii) && window_radii >= 2,
             "BallTrackOptions.window_radii must be >= 2 (got {})", window_radii);
  FV_REQUIRE(min_window_px >= 8, "BallTrackOptions.min_window_px must be >= 8 (got {})",
             min_window_px);
}

namespace {

// Where a camera stage looks next: the window around the ball's predicted image position.
class ImageTrack {
 public:
  explicit ImageTrack(const BallTrackOptions& o) : o_(o) {}
  // The window for the next frame, or an empty rectangle for the whole frame.
  cv::Rect Window(const cv::Size& image) const {
    if (!o_.enabled || !active_ || since_full_ + 1 >= o_.full_scan_every) return {};
    const Eigen::Vector2d p = centre_ + velocity_;
    const double half =
        std::max<double>(o_.min_window_px, o_.window_radii * radius_ + velocity_.norm());
    const int x0 = static_cast<int>(std::floor(p.x() - half));
    const int y0 = static_cast<int>(std::floor(p.y() - half));
    const int x1 = static_cast<int>(std::ceil(p.x() + half));
    const int y1 = static_cast<int>(std::ceil(p.y() + half));
    const cv::Rect r = cv::Rect(x0, y0, x1 - x0, y1 - y0) & cv::Rect(cv::Point(0, 0), image);
    return r.area() > 0 ? r : cv::Rect();
  }
  void Update(const std::vector<BallObservation>& obs, bool full) {
    since_full_ = full ? 0 : since_full_ + 1;
    const BallObservation* best = nullptr;
    for (const BallObservation& b : obs) {
      if (!b.weak && (best == nullptr || b.score > best->score)) best = &b;
    }
    if (best == nullptr) {
      active_ = false;
      return;
    }
    velocity_ = active_ ? Eigen::Vector2d(best->centre_px - centre_) : Eigen::Vector2d::Zero();
    centre_ = best->centre_px;
    radius_ = std::max(best->radius_px, 2.0);
    active_ = true;
  }

 private:
  BallTrackOptions o_;
  bool active_ = false;
  int since_full_ = 0;
  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity_ = Eigen::Vector2d::Zero();
  double radius_ = 0.0;
};

}  // namespace

BallPipelineSummary RunBallPipeline(const std::vector<Camera>& cameras,
                                    std::vector<std::unique_ptr<FrameSource>>& sources,
                                    const std::vector<BallDetectFn>& detectors,
                                    const BallPipelineOptions& options,
                                    const std::function<void(const BallFrame&)>& on_frame) {
  std::vector<BallRegionDetectFn> region_fns;
  for (const BallDetectFn& fn : detectors) {
    if (!fn) {
      region_fns.emplace_back();
      continue;
    }
    region_fns.push_back([fn](const cv::Mat& bgr, const cv::Rect&) { return fn(bgr); });
  }
  BallPipelineOptions o = options;
  o.track.enabled = false;  // these detectors search whole frames
  return RunBallPipelineTracked(cameras, sources, region_fns, o, on_frame);
}

BallPipelineSummary RunBallPipelineTracked(const std::vector<Camera>& cameras,
                                           std::vector<std::unique_ptr<FrameSource>>& sources,
                                           const std::vector<BallRegionDetectFn>& detectors,
                                           const BallPipelineOptions& options,
                                           const std::function<void(const BallFrame&)>& on_frame) {
  options.Check();
  const int n = static_cast<int>(cameras.size());
  FV_REQUIRE(n >= 1, "ball pipeline: no cameras");
  FV_REQUIRE(sources.size() == cameras.size() && detectors.size() == cameras.size(),
             "ball pipeline: {} cameras but {} videos and {} detectors", n, sources.size(),
             detectors.size());
  for (int c = 0; c < n; ++c) {
    FV_REQUIRE(sources[c] != nullptr && detectors[c] != nullptr,
               "ball pipeline: camera {} has no video or detector", c);
    const cv::Size size = sources[c]->FrameSize();
    FV_REQUIRE(size.width == cameras[c].width && size.height == cameras[c].height,
               "camera {} ('{}') is calibrated for {}x{} but video '{}' is {}x{}", c,
               cameras[c].name, cameras[c].width, cameras[c].height, sources[c]->name(), size.width,
               size.height);
  }
  BallPipelineSummary summary;
  summary.num_cameras = n;
  for (int c = 0; c < n; ++c) {
    summary.camera_names.push_back(cameras[c].name.empty() ? fmt::format("camera {}", c)
                                                           : cameras[c].name);
  }
  summary.used_per_camera.assign(n, 0);
  summary.candidates_per_camera.assign(n, 0);
  summary.queue_drops.assign(n, 0);
  summary.full_scans.assign(n, 0);
  summary.bad_frames.assign(n, 0);
  summary.first_bad_frame.assign(n, "");
  summary.window_scans.assign(n, 0);

  std::vector<std::unique_ptr<BoundedQueue<CameraMessage>>> queues;
  queues.reserve(n);
  for (int c = 0; c < n; ++c) {
    queues.push_back(std::make_unique<BoundedQueue<CameraMessage>>(options.queue_capacity,
                                                                   options.queue_policy));
  }
  std::atomic<bool> stop{false};
  std::mutex error_mutex;
  std::exception_ptr error;
  auto fail = [&](const std::exception_ptr& e) {
    {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = e;
    }
    stop = true;
    for (auto& q : queues) q->Close();
  };
  long long total = -1;
  for (const auto& s : sources) total = std::max(total, s->FrameCount());
  if (options.max_frames > 0) total = total > 0 ? std::min(total, options.max_frames) : -1;

  const auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> threads;
  threads.reserve(n);
  for (int c = 0; c < n; ++c) {
    threads.emplace_back([&, c] {
      try {
        SourceFrame in;
        cv::Mat decoded;  // encoded frames are decoded here, in full or a window
        JpegRegionDecoder decoder;
        ImageTrack track(options.track);
        const cv::Size size(cameras[c].width, cameras[c].height);
        CameraMessage m;
        m.camera = c;
        long long count = 0;
        while (!stop && (options.max_frames == 0 || count < options.max_frames) &&
               sources[c]->ReadFrame(&in)) {
          m.frame = in.frame;
          m.time_s = in.time_s;
          const bool encoded = !in.jpeg.empty();
          // The frame's pixels in `roi` (empty: all); null for a damaged encoded frame, which is
          // reported and sent without candidates while the video goes on.
          auto check_size = [&](const cv::Size& got) {
            FV_REQUIRE(got == size, "video '{}' frame {} is {}x{}, camera {} is {}x{}",
                       sources[c]->name(), m.frame, got.width, got.height, c, size.width,
                       size.height);
          };
          auto image = [&](const cv::Rect& roi) -> const cv::Mat* {
            if (!encoded) return &in.bgr;
            const std::string what =
                fmt::format("video '{}' frame {}", sources[c]->name(), in.frame);
            try {
              decoder.Decode(in.jpeg.data(), in.jpeg.size(), roi, &decoded, what);
            } catch (const Error& e) {
              // A readable header of another size is the wrong video, not a damaged frame.
              cv::Size got = size;
              try {
                got = JpegRegionDecoder::ReadSize(in.jpeg.data(), in.jpeg.size(), what);
              } catch (const Error&) {
              }
              check_size(got);
              if (summary.bad_frames[c]++ == 0) summary.first_bad_frame[c] = e.what();
              return nullptr;
            }
            return &decoded;
          };
          const cv::Rect window = track.Window(size);
          bool full = window.empty();
          const cv::Mat* frame = image(window);
          m.candidates.clear();
          if (frame != nullptr) {
            check_size(frame->size());
            if (!full) {
              m.candidates = detectors[c](*frame, window);
              ++summary.window_scans[c];
              full = !HasAccepted(m.candidates);
            }
            if (full && !window.empty()) frame = image(cv::Rect());
            if (frame == nullptr) {
              m.candidates.clear();
            } else if (full) {
              m.candidates = detectors[c](*frame, cv::Rect());
              ++summary.full_scans[c];
            }
          }
          full = full || frame == nullptr;
          track.Update(m.candidates, full);
          ++count;
          if (!queues[c]->Push(m)) break;
        }
        queues[c]->Close();
      } catch (...) {
        fail(std::current_exception());
      }
    });
  }

  // The fusion stage, in this thread.
  double sum_err = 0;
  try {
    FrameSynchronizer sync(n, options.sync);
    BallPredictor predictor;
    Progress progress("ball", total, "frames", options.progress);
    while (!stop) {
      while (auto group = sync.Next()) {
        for (int c = 0; c < n; ++c) {
          if (!group->cameras[c]) continue;
          for (const BallObservation& o : group->cameras[c]->candidates) {
            summary.candidates_per_camera[c] += !o.weak;
          }
        }
        const auto prior = predictor.Predict(group->frame);
        const BallFrame f =
            FuseFrame(cameras, *group, options.triangulation, prior ? &*prior : nullptr);
        if (f.result.ok() && !f.result.on_ground) predictor.Add(f.frame, f.result.point_world);
        ++summary.frames;
        if (f.result.ok()) {
          ++summary.frames_with_position;
          if (f.result.on_ground) ++summary.ground_positions;
          if (f.result.weak_views > 0) ++summary.weak_positions;
          sum_err += f.result.rms_px;
          for (const auto& v : f.result.views) ++summary.used_per_camera[v.camera];
        } else if (f.cameras_with_blobs < 2) {
          ++summary.frames_few_blobs;
        } else {
          ++summary.frames_inconsistent;
        }
        on_frame(f);
        progress.Update(summary.frames);
      }
      if (sync.Done()) break;
      const int c = sync.Waiting();
      if (c < 0) break;  // cannot happen: Next() decides when nobody is waiting
      if (auto m = queues[c]->Pop()) {
        sync.Add(std::move(*m));
      } else if (!stop) {
        sync.EndOfStream(c);
      }
    }
    progress.Finish();
    summary.sync = sync.report();
  } catch (...) {
    fail(std::current_exception());
  }
  stop = true;
  for (auto& q : queues) q->Close();
  for (auto& t : threads) t.join();
  if (error) std::rethrow_exception(error);
  for (int c = 0; c < n; ++c) summary.queue_drops[c] = queues[c]->dropped();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.fps = summary.seconds > 0 ? summary.frames / summary.seconds : 0.0;
  summary.mean_err_px = summary.frames_with_position ? sum_err / summary.frames_with_position : 0;
  return summary;
}

}  // namespace fv
