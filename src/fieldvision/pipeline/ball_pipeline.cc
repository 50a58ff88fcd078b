#include "fieldvision/pipeline/ball_pipeline.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"

namespace fv::pipeline {

void BallPipelineOptions::Check() const {
  sync.Check();
  FV_REQUIRE(queue_capacity >= 1 && queue_capacity <= 10000,
             "BallPipelineOptions.queue_capacity must be in [1, 10000] (got {})", queue_capacity);
  FV_REQUIRE(max_frames >= 0, "BallPipelineOptions.max_frames must be >= 0 (got {})", max_frames);
  FV_REQUIRE(second_pass_lag_s >= 0 && std::isfinite(second_pass_lag_s),
             "BallPipelineOptions.second_pass_lag_s must be finite and >= 0 (got {})",
             second_pass_lag_s);
  triangulation.Check();
  track.Check();
  hint.Check();
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
  if (hovering_dropped > 0) {
    s += fmt::format(
        "{} airborne points dropped because they stood still (ball-coloured things that two "
        "cameras agree on; a ball cannot hover)\n",
        hovering_dropped);
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
  long long full = 0, window = 0, fitted = 0;
  for (long long f : full_scans) full += f;
  for (long long w : window_scans) window += w;
  for (long long g : guided) fitted += g;
  if (window > 0) {
    s += fmt::format(", {} camera frames searched in a window around the ball, {} whole", window,
                     full);
  }
  if (fitted > 0) {
    s += fmt::format(", {} balls fitted where expected (not found by the search)", fitted);
  }
  for (const std::string& p : sync.Problems(camera_names)) s += "\nsync: " + p;
  for (int c = 0; c < num_cameras && c < static_cast<int>(bad_frames.size()); ++c) {
    if (bad_frames[c] > 0) {
      s += fmt::format("\n{}: {} frames could not be decoded (first: {})", camera_names[c],
                       bad_frames[c], first_bad_frame[c]);
    }
  }
  return s;
}

BallPipelineSummary RunBallPipeline(const std::vector<camera::Camera>& cameras,
                                    std::vector<std::unique_ptr<io::FrameSource>>& sources,
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

void CheckBallPipelineInputs(const std::vector<camera::Camera>& cameras,
                             const std::vector<std::unique_ptr<io::FrameSource>>& sources,
                             const std::vector<BallRegionDetectFn>& detectors) {
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
}

BallPipelineSummary EmptyBallPipelineSummary(const std::vector<camera::Camera>& cameras) {
  const int n = static_cast<int>(cameras.size());
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
  summary.guided.assign(n, 0);
  return summary;
}

long long ExpectedPipelineFrames(const std::vector<long long>& frame_counts, long long max_frames) {
  long long total = -1;
  for (long long count : frame_counts) total = std::max(total, count);
  if (max_frames > 0) total = total > 0 ? std::min(total, max_frames) : -1;
  return total;
}

void ReadCameraStream(io::FrameSource& source, CameraStage& stage,
                      BoundedQueue<CameraMessage>& queue, long long max_frames,
                      const std::function<bool()>& stopping) {
  io::SourceFrame in;
  long long count = 0;
  while (!stopping() && (max_frames == 0 || count < max_frames) && source.ReadFrame(&in)) {
    ++count;
    if (!queue.Push(stage.Process(in))) break;
  }
  queue.Close();
}

void FuseCameraQueues(const std::vector<camera::Camera>& cameras, const CameraQueues& queues,
                      const BallPipelineOptions& options, long long total,
                      const std::function<bool()>& stopping,
                      const std::function<void(const BallFrame&)>& on_frame,
                      BallPipelineSummary* summary, BallHintBoard* hints) {
  FrameSynchronizer sync(static_cast<int>(cameras.size()), options.sync);
  FusionStage fusion(cameras, options.triangulation);
  util::Progress progress("ball", total, "frames", options.progress);
  const bool second_pass = options.second_pass && options.queue_policy == QueuePolicy::kBlock;
  FusionStage again(cameras, options.triangulation);
  std::deque<SyncedFrame> pending;  // fused once, waiting for the second pass
  double remembered_s = -std::numeric_limits<double>::infinity();
  // The second pass over the frames the first one has passed by the lag (all at the end).
  const auto fuse_again = [&](double up_to_s) {
    remembered_s = again.RememberHovering(fusion, remembered_s);
    while (!pending.empty() && pending.front().time_s <= up_to_s && !stopping()) {
      on_frame(again.Fuse(pending.front()));
      pending.pop_front();
    }
  };
  while (!stopping()) {
    while (auto group = sync.Next()) {
      const BallFrame f = fusion.Fuse(*group);
      if (hints != nullptr && f.result.ok() && !f.result.on_ground) {
        hints->Publish(f.time_s, f.result.point_world, options.triangulation.ball_radius_m);
      }
      if (second_pass) {
        const double now_s = group->time_s;
        pending.push_back(std::move(*group));
        fuse_again(now_s - options.second_pass_lag_s);
      } else {
        on_frame(f);
      }
      progress.Update(fusion.stats().frames);
      if (options.control != nullptr) {
        options.control->Report({"ball", fusion.stats().frames, total, "frames", ""});
      }
    }
    if (sync.Done()) break;
    const int c = sync.Waiting();
    if (c < 0) break;  // cannot happen: Next() decides when nobody is waiting
    if (auto m = queues[c]->Pop()) {
      if (hints != nullptr) hints->Popped(c);
      if (options.on_message) options.on_message(*m);
      sync.Add(std::move(*m));
    } else if (!stopping()) {
      sync.EndOfStream(c);
    }
  }
  progress.Finish();
  summary->sync = sync.report();
  if (!second_pass) {
    AddFusionStats(fusion.stats(), summary);
    return;
  }
  fuse_again(std::numeric_limits<double>::infinity());
  AddFusionStats(again.stats(), summary);
}

void AddFusionStats(const FusionStats& f, BallPipelineSummary* summary) {
  summary->frames = f.frames;
  summary->frames_with_position = f.frames_with_position;
  summary->ground_positions = f.ground_positions;
  summary->weak_positions = f.weak_positions;
  summary->hovering_dropped = f.hovering_dropped;
  summary->frames_few_blobs = f.frames_few_blobs;
  summary->frames_inconsistent = f.frames_inconsistent;
  summary->used_per_camera = f.used_per_camera;
  summary->candidates_per_camera = f.candidates_per_camera;
  summary->mean_err_px = f.frames_with_position ? f.sum_err_px / f.frames_with_position : 0;
}

namespace {

// The first error of any stage; stopping closes every queue so that no stage waits.
class StageErrors {
 public:
  StageErrors(const CameraQueues& queues, const JobControl* control, BallHintBoard* hints)
      : queues_(queues), control_(control), hints_(hints) {}
  void Fail(const std::exception_ptr& e) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = e;
    }
    StopAll();
  }
  void StopAll() {
    stop_ = true;
    for (auto& q : queues_) q->Close();
    if (hints_ != nullptr) hints_->Close();
  }
  bool Stopping() const { return stop_ || StopRequested(control_); }
  void RethrowFirst() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  const CameraQueues& queues_;
  const JobControl* control_;
  BallHintBoard* hints_;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::exception_ptr error_;
};

}  // namespace

BallPipelineSummary RunBallPipelineTracked(const std::vector<camera::Camera>& cameras,
                                           std::vector<std::unique_ptr<io::FrameSource>>& sources,
                                           const std::vector<BallRegionDetectFn>& detectors,
                                           const BallPipelineOptions& options,
                                           const std::function<void(const BallFrame&)>& on_frame,
                                           const std::vector<BallGuidedFn>& guided) {
  options.Check();
  CheckBallPipelineInputs(cameras, sources, detectors);
  FV_REQUIRE(guided.empty() || guided.size() == cameras.size(),
             "ball pipeline: {} cameras but {} guided fits", cameras.size(), guided.size());
  const int n = static_cast<int>(cameras.size());
  BallPipelineSummary summary = EmptyBallPipelineSummary(cameras);
  CameraQueues queues;
  std::vector<CameraStage> stages;
  std::vector<long long> frame_counts;
  queues.reserve(n);
  stages.reserve(n);
  for (int c = 0; c < n; ++c) {
    queues.push_back(std::make_unique<BoundedQueue<CameraMessage>>(options.queue_capacity,
                                                                   options.queue_policy));
    stages.emplace_back(c, cameras[c], detectors[c], options.track, sources[c]->name(),
                        guided.empty() ? BallGuidedFn() : guided[c]);
    frame_counts.push_back(sources[c]->FrameCount());
  }
  // The fusion's hints, with tracking windows on posed cameras: offline deterministic (waits).
  const bool posed = std::all_of(cameras.begin(), cameras.end(),
                                 [](const camera::Camera& c) { return c.has_pose; });
  std::optional<BallHintBoard> hints;
  if (options.hints && options.track.enabled && posed) {
    hints.emplace(n, options.hint, options.queue_policy == QueuePolicy::kBlock);
    for (CameraStage& s : stages) s.SetHints(&*hints);
  }
  StageErrors errors(queues, options.control, hints ? &*hints : nullptr);
  const std::function<bool()> stopping = [&errors] { return errors.Stopping(); };
  const long long total = ExpectedPipelineFrames(frame_counts, options.max_frames);

  const auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> threads;
  threads.reserve(n);
  for (int c = 0; c < n; ++c) {
    threads.emplace_back([&, c] {
      try {
        ReadCameraStream(*sources[c], stages[c], *queues[c], options.max_frames, stopping);
      } catch (...) {
        errors.Fail(std::current_exception());
      }
    });
  }
  try {  // the fusion stage, in this thread
    FuseCameraQueues(cameras, queues, options, total, stopping, on_frame, &summary,
                     hints ? &*hints : nullptr);
  } catch (...) {
    errors.Fail(std::current_exception());
  }
  errors.StopAll();
  for (auto& t : threads) t.join();
  errors.RethrowFirst();
  for (int c = 0; c < n; ++c) {
    summary.queue_drops[c] = queues[c]->dropped();
    const CameraStageStats& st = stages[c].stats();
    summary.full_scans[c] = st.full_scans;
    summary.window_scans[c] = st.window_scans;
    summary.guided[c] = st.guided;
    summary.bad_frames[c] = st.bad_frames;
    summary.first_bad_frame[c] = st.first_bad_frame;
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.fps = summary.seconds > 0 ? summary.frames / summary.seconds : 0.0;
  return summary;
}

}  // namespace fv::pipeline
