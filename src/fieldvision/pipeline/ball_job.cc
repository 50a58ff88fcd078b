#include "fieldvision/pipeline/ball_job.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/camera/pose_range.h"
#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/field/field.h"
#include "fieldvision/pipeline/detections_job.h"
#include "fieldvision/pipeline/flight_refiner.h"
#include "fieldvision/recon/ball_csv.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

namespace fv::pipeline {

void BallJobOptions::Check() const {
  FV_REQUIRE(!cameras.empty(), "ball: give at least one --camera and --video pair");
  FV_REQUIRE(cameras.size() == videos.size(), "ball: {} --camera but {} --video (they pair up)",
             cameras.size(), videos.size());
  FV_REQUIRE(cameras.size() >= 2 || pipeline.triangulation.single_camera_ground,
             "ball: one camera gives no 3D position: give 2 or more --camera/--video pairs (or "
             "--ground for positions on the ground)");
  for (size_t i = 0; i < videos.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      // One file under two names (./v.avi and v.avi, a link) is the same video.
      FV_REQUIRE(!util::SameFile(videos[i], videos[j]), "ball: video '{}' is given twice (as '{}')",
                 videos[i], videos[j]);
    }
  }
  FV_REQUIRE(timestamps.empty() || timestamps.size() == videos.size(),
             "ball: {} --timestamps for {} videos (give one per video or none)", timestamps.size(),
             videos.size());
  FV_REQUIRE(std::isfinite(fps) && fps >= 0 && fps <= 100000,
             "ball: --fps must be a frame rate in (0, 100000] (got {})", fps);
  FV_REQUIRE(std::isfinite(ball_diameter_m) && ball_diameter_m > 0 && ball_diameter_m < 2,
             "ball: --ball-diameter must be in (0, 2) metres (got {})", ball_diameter_m);
  FV_REQUIRE(!out.empty(), "ball: --out is required");
  FV_REQUIRE(detections_out.empty() || detections_out.size() == cameras.size(),
             "ball: {} --write-detections for {} cameras (give one per camera or none)",
             detections_out.size(), cameras.size());
  FV_REQUIRE(sync == "frame" || sync == "time", "ball: --sync must be 'frame' or 'time' (got '{}')",
             sync);
  dnn.Check();
  background_options.Check();
  pipeline.Check();
  eval.Check();
  FV_REQUIRE(std::isfinite(bundle_sigma_px) && bundle_sigma_px > 0,
             "ball: bundle_sigma_px must be > 0 (got {})", bundle_sigma_px);
}

detect::BallDetectorOptions TrackingDetectorOptions(double ball_diameter_m,
                                                    const std::string& colour) {
  detect::BallDetectorOptions o;
  o.diameter_m = ball_diameter_m;
  o.colour = colour;
  o.small.mode = "off";
  return o;
}

camera::Camera ReadRigCamera(const std::string& path) {
  camera::Camera camera = camera::ReadCameraYaml(path);
  if (camera.name.empty()) camera.name = std::filesystem::path(path).stem().string();
  if (camera.name.empty()) camera.name = path;
  FV_REQUIRE(camera.has_pose,
             "camera file '{}' has no pose (rvec, tvec): calibrate its extrinsics first", path);
  camera::CheckCameraNearOrigin(camera, "camera file '" + path + "'");
  return camera;
}

void CheckRigSpread(const std::vector<camera::Camera>& cameras,
                    const std::vector<std::string>& files) {
  constexpr double kApartM = 0.01;
  double widest_m = 0;
  for (size_t i = 0; i < cameras.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      widest_m =
          std::max(widest_m, (cameras[i].CentreInWorld() - cameras[j].CentreInWorld()).norm());
    }
  }
  FV_REQUIRE(cameras.size() < 2 || widest_m >= kApartM,
             "camera files '{}' and '{}' put the cameras at one place ({:.3f} m apart at most): "
             "rays from one place cross nowhere; give cameras that see the field from different "
             "places",
             files.front(), files.back(), widest_m);
}

namespace {

recon::BallObservation Observation(const detect::BallCandidate& b) {
  recon::BallObservation obs;
  // A ball the colour checks rejected and a low network score rescued completes positions only:
  // a cone the network took for a ball at 0.1-0.3, seen by all four cameras of the kick render,
  // outvoted the ball that three saw.
  obs.weak = !b.accepted || b.rescued;
  obs.centre_px = b.centre_px;
  obs.radius_px = b.radius_px;
  obs.sigma_px = std::max(b.sigma_px, 0.05);
  obs.score = b.score;
  obs.background_change = b.background_change;
  return obs;
}

// Accepted candidates, then the best few weak ones (fusion uses those only to complete a
// position that an accepted candidate of another camera starts).
std::vector<recon::BallObservation> Observations(
    const std::vector<detect::BallCandidate>& candidates) {
  constexpr int kMaxWeak = 3;
  std::vector<recon::BallObservation> out;
  int weak = 0;
  for (const detect::BallCandidate& b : candidates) {
    if (!b.accepted && !(b.weak && weak < kMaxWeak)) continue;
    weak += !b.accepted;
    out.push_back(Observation(b));
  }
  return out;
}

// A message's candidates as DET.csv rows.
void WriteDetections(const CameraMessage& m, util::CsvWriter* csv) {
  for (const recon::BallObservation& b : m.candidates) {
    *csv << m.frame << m.time_s << b.centre_px.x() << b.centre_px.y() << b.radius_px << b.score;
    csv->EndRow();
  }
}

// FitAt of either detector as a camera stage's guided fit.
template <typename Detector>
BallGuidedFn GuidedFnFor(std::shared_ptr<Detector> detector) {
  return [det = std::move(detector)](const cv::Mat& bgr, const cv::Rect& roi,
                                     const Eigen::Vector2d& centre_px,
                                     double radius_px) -> std::optional<recon::BallObservation> {
    const std::optional<detect::BallCandidate> c = det->FitAt(bgr, roi, centre_px, radius_px);
    if (!c) return std::nullopt;
    return Observation(*c);
  };
}

// The job's videos, each checked against its camera's size (a camera fitted to an encoder's
// cropped padding, its note in `camera_notes`). --live on files: a file is not live; each is
// played at its own frame rate from one common start (as cameras would deliver it), so frames
// drop only when fusion is slower than that.
std::vector<std::unique_ptr<io::FrameSource>> OpenBallVideos(
    const BallJobOptions& o, std::vector<camera::Camera>& cameras,
    std::vector<std::string>& camera_notes) {
  std::vector<std::unique_ptr<io::FrameSource>> sources;
  const double live_start_s =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count() +
      0.5;
  for (size_t c = 0; c < cameras.size(); ++c) {
    io::FrameSourceOptions vo;
    vo.realtime = o.live;
    vo.start_at_s = o.live ? live_start_s : 0.0;
    if (!o.timestamps.empty()) {
      vo.time = io::TimeSource::kCsv;
      vo.timestamps_csv = o.timestamps[c];
    } else if (o.sync == "time") {
      vo.time = io::TimeSource::kContainer;
    }
    vo.encoded = true;  // MJPG: libjpeg-turbo, and only around the tracked ball
    auto src = io::OpenFrameSource(o.videos[c], vo);
    // Times are taken from the videos, never assumed (flight speeds scale with them): --fps
    // gives a rate to those without one and must agree with the others'.
    if (!src->rate_known() && o.fps > 0) {
      vo.fps = o.fps;
      src = io::OpenFrameSource(o.videos[c], vo);
    }
    FV_REQUIRE(src->rate_known(),
               "video '{}' has no frame rate of its own (an image sequence, or a container "
               "without one): give --fps or --timestamps",
               o.videos[c]);
    FV_REQUIRE(o.fps <= 0 || std::abs(src->fps() - o.fps) <= 0.01 * o.fps,
               "--fps {:g} but video '{}' runs at {:.4g} frames/s (--fps is for image sequences; "
               "--timestamps gives any video's times)",
               o.fps, o.videos[c], src->fps());
    camera_notes.push_back(io::FitCameraToSource(*src, cameras[c], o.cameras[c]));
    sources.push_back(std::move(src));
  }
  // Frames paired by index are of one time only at one frame rate (else the fused times go back
  // and forth where the shorter video ends).
  for (size_t c = 1; o.sync == "frame" && o.timestamps.empty() && c < sources.size(); ++c) {
    const double a = sources[0]->fps(), b = sources[c]->fps();
    FV_REQUIRE(std::abs(a - b) <= 0.01 * std::max(a, b),
               "ball: --sync frame pairs frames by index, but '{}' runs at {:.4g} frames/s and "
               "'{}' at {:.4g}: give each video's --timestamps",
               o.videos[0], a, o.videos[c], b);
  }
  return sources;
}

}  // namespace

std::string BallJobResult::NoPositionWarning() const {
  if (rows_written > 0) return "";
  const BallPipelineSummary& s = summary;
  std::string per_camera;
  for (size_t c = 0; c < s.candidates_per_camera.size(); ++c) {
    per_camera += fmt::format("{}{} {}", c > 0 ? ", " : "",
                              c < s.camera_names.size() ? s.camera_names[c] : "?",
                              s.candidates_per_camera[c]);
  }
  return fmt::format(
      "no ball position in {} frames ({} with candidates in fewer than 2 cameras, {} whose "
      "candidates disagree; candidates per camera: {}): the output has its header only (check "
      "--color and the cameras' poses)",
      s.frames, s.frames_few_blobs, s.frames_inconsistent, per_camera);
}

BallRegionDetectFn BallDetectFnFor(std::shared_ptr<detect::BallDetector> detector) {
  return [det = std::move(detector)](const cv::Mat& bgr, const cv::Rect& roi) {
    return Observations(det->Detect(bgr, roi));
  };
}

BallRegionDetectFn BallDetectFnFor(std::shared_ptr<detect::AnyBallDetector> detector) {
  return [det = std::move(detector)](const cv::Mat& bgr, const cv::Rect& roi) {
    return Observations(det->Detect(bgr, roi));
  };
}

BallGuidedFn BallGuidedFnFor(std::shared_ptr<detect::BallDetector> detector) {
  return GuidedFnFor(std::move(detector));
}

BallGuidedFn BallGuidedFnFor(std::shared_ptr<detect::AnyBallDetector> detector) {
  return GuidedFnFor(std::move(detector));
}

BallJobResult RunBallJob(const BallJobOptions& o) {
  o.Check();
  FV_REQUIRE(o.truth.empty() || std::filesystem::exists(o.truth), "truth file '{}' does not exist",
             o.truth);
  // A bad truth file fails before anything is written (read as both truth and estimate, it is
  // checked for columns and values).
  std::optional<util::CsvTable> truth;
  if (!o.truth.empty()) {
    truth = util::CsvTable::Read(o.truth);
    FV_REQUIRE(truth->rows() > 0, "truth file '{}' has a header but no rows", o.truth);
    recon::CheckBallTrackRanges(*truth);
    recon::EvaluateBall(*truth, *truth, o.eval);
  }
  const int n = static_cast<int>(o.cameras.size());
  std::vector<camera::Camera> cameras;
  cameras.reserve(n);
  for (int c = 0; c < n; ++c) cameras.push_back(ReadRigCamera(o.cameras[c]));
  if (!o.pipeline.triangulation.single_camera_ground) CheckRigSpread(cameras, o.cameras);
  std::optional<field::FieldModel> field;
  if (!o.field.empty()) field = field::LoadField(o.field);
  // Open every video (and check its size) before starting any thread.
  std::vector<std::string> frames_notes;  // the cameras' fits and each video's first frame's
  std::vector<std::unique_ptr<io::FrameSource>> sources = OpenBallVideos(o, cameras, frames_notes);
  for (size_t c = 0; c < sources.size(); ++c) {
    frames_notes[c] = util::JoinNonEmpty({frames_notes[c], sources[c]->FramesNote()}, "; ");
  }
  const detect::BallDetectorOptions dopt = TrackingDetectorOptions(o.ball_diameter_m, o.colour);
  std::vector<BallRegionDetectFn> detect_fns;
  std::vector<BallGuidedFn> guided_fns;
  std::vector<std::shared_ptr<detect::CameraBackground>> backgrounds;
  for (int c = 0; c < n; ++c) {
    auto detector = std::make_shared<detect::AnyBallDetector>(dopt, o.dnn, &cameras[c],
                                                              field ? &*field : nullptr);
    backgrounds.push_back(detect::UseCameraBackground(
        o.background && !o.live, o.videos[c], &cameras[c], detector.get(), o.background_options));
    // Nearly every video asks for it (boards, far balls): built while the pipeline starts.
    if (backgrounds.back()) backgrounds.back()->Start();
    detect_fns.push_back(BallDetectFnFor(detector));
    guided_fns.push_back(BallGuidedFnFor(detector));
  }
  BallPipelineOptions popt = o.pipeline;
  popt.sync.mode = o.sync == "time" ? SyncMode::kTimestamp : SyncMode::kFrameIndex;
  popt.queue_policy = o.live ? QueuePolicy::kDropOldest : QueuePolicy::kBlock;
  popt.triangulation.ball_radius_m = 0.5 * o.ball_diameter_m;
  if (field) {
    // A position off the field (beyond the detector's margin) or above its highest ball is none.
    const double hx = 0.5 * field->length_m + dopt.field_margin_m;
    const double hy = 0.5 * field->width_m + dopt.field_margin_m;
    popt.triangulation.allowed_region = Eigen::AlignedBox3d(
        Eigen::Vector3d(-hx, -hy, -1e3), Eigen::Vector3d(hx, hy, dopt.max_height_m));
  }

  // Each camera's accepted candidates as DET.csv, committed with BALL.csv.
  std::vector<std::unique_ptr<util::AtomicOutput>> det_files;
  std::vector<std::unique_ptr<util::CsvWriter>> det_csvs;
  for (const std::string& path : o.detections_out) {
    det_files.push_back(std::make_unique<util::AtomicOutput>(path, "--write-detections"));
    det_csvs.push_back(std::make_unique<util::CsvWriter>(
        det_files.back()->temp_path(),
        std::vector<std::string>{"frame", "time_s", "u", "v", "radius_px", "score"}));
  }
  // Offline, each flight is refined on the cameras' accepted candidates (flight_refiner.h: piece
  // by piece of the track, in bounded memory) and its rows written then; live, as the fusion gives
  // them.
  const bool bundle = o.bundle && !o.live;
  BallJobResult result;
  // Write to a temporary file beside the output, rename at the end: a failed run (a truncated
  // video, a bad timestamp) leaves neither a half file nor a temporary one.
  util::AtomicWrite(o.out, [&](const std::string& temp_path) {
    util::CsvWriter csv(temp_path, recon::BallCsvColumns(), 6);
    const auto write = [&](const recon::BallSample& s) {
      csv << s.frame << s.time_s << s.ball_in_world.x() << s.ball_in_world.y()
          << s.ball_in_world.z() << s.n_cams << s.err_px;
      csv.EndRow();
      ++result.rows_written;
    };
    std::optional<FlightRefiner> refiner;
    if (bundle) {
      FlightRefinerOptions ro;
      ro.ball_diameter_m = o.ball_diameter_m;
      ro.sigma_px = o.bundle_sigma_px;
      refiner.emplace(cameras, ro, write);
    }
    if (!det_csvs.empty() || refiner) {
      popt.on_message = [&](const CameraMessage& m) {
        CameraMessage kept = m;
        std::erase_if(kept.candidates, [](const recon::BallObservation& b) { return b.weak; });
        if (!det_csvs.empty()) WriteDetections(kept, det_csvs.at(m.camera).get());
        if (refiner) refiner->AddMessage(std::move(kept));
      };
    }
    result.summary = RunBallPipelineTracked(
        cameras, sources, detect_fns, popt,
        [&](const BallFrame& f) {
          if (!f.result.ok()) return;
          if (refiner) {
            refiner->AddSample(BallSampleOf(f));
          } else {
            write(BallSampleOf(f));
          }
        },
        guided_fns);
    if (refiner) {
      refiner->Finish();
      result.bundle = refiner->totals();
    }
    csv.Close();
  });
  for (size_t c = 0; c < det_files.size(); ++c) det_files[c]->CloseAndCommit(*det_csvs[c]);
  result.frames_notes = std::move(frames_notes);
  for (const auto& b : backgrounds) {
    result.backgrounds.push_back(detect::NeededBackgroundSummary(b));
  }
  if (truth) result.eval = recon::EvaluateBall(*truth, util::CsvTable::Read(o.out), o.eval);
  return result;
}

}  // namespace fv::pipeline
