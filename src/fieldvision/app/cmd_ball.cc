// `fieldvision ball`: the ball in 3D from 2..N synchronised cameras (pipeline/ball_job.h).
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "fieldvision/app/ball_options.h"
#include "fieldvision/app/command.h"
#include "fieldvision/app/detector_options.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/pipeline/ball_job.h"
#include "fieldvision/pipeline/ball_overlay.h"
#include "fieldvision/pipeline/detections_job.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::app {
namespace {

struct BallCliOptions {
  pipeline::BallJobOptions job;
  bool rows = false;
  pipeline::DetectionsJobOptions det;       // with --detections instead of --video
  pipeline::BallOverlayOptions draw;        // --draw DIR
  std::optional<util::NewFolder> draw_dir;  // ... a new folder, removed if the run fails empty
};

// --draw: each camera's video with the 3D ball and its candidates (pipeline/ball_overlay.h),
// frames paired by index, in a new or empty folder (nothing of the user's replaced); the
// candidates drawn are those --write-detections writes (into the folder, NAME_det.csv, when it
// is not given). Names from the camera files' names (pipeline::DrawNames).
void PrepareDraw(BallCliOptions& o) {
  if (o.draw.dir.empty()) return;
  FV_REQUIRE(o.job.timestamps.empty() && o.job.sync == "frame" && !o.job.live,
             "ball: --draw pairs each camera's frames with BALL.csv by index: it needs --sync "
             "frame (no --timestamps) and no --live");
  for (const std::string& video : o.job.videos) {
    std::error_code ec;
    FV_REQUIRE(std::filesystem::exists(video, ec) || !io::ListImageSequence(video).empty(),
               "ball: --draw reads the videos again after the run: '{}' is no file and matches "
               "no image (a live source cannot be read again)",
               video);
  }
  o.draw.ball_diameter_m = o.job.ball_diameter_m;
  o.draw.max_frames = o.job.pipeline.max_frames;
  o.draw.fps = o.job.fps;  // image sequences' rate (videos keep their own, checked by the job)
  o.draw.progress = o.job.pipeline.progress;
  o.draw.Check();
  std::vector<std::string> stems;
  for (const std::string& cam : o.job.cameras) {
    stems.push_back(std::filesystem::path(cam).stem().string());
  }
  o.draw.names = pipeline::DrawNames(stems);
  o.draw_dir.emplace(o.draw.dir, "--draw");
  if (!o.job.detections_out.empty()) return;
  for (const std::string& name : o.draw.names) {
    o.job.detections_out.push_back(fmt::format("{}/{}_det.csv", o.draw.dir, name));
  }
}

void Draw(const BallCliOptions& o) {
  std::vector<camera::Camera> cameras;
  for (const std::string& path : o.job.cameras) cameras.push_back(pipeline::ReadRigCamera(path));
  const pipeline::BallOverlayResult r =
      pipeline::DrawBallOverlays(cameras, o.job.videos, o.job.out, o.job.detections_out, o.draw);
  std::cout << r.Summary() << "\n";
}

void RunDetections(BallCliOptions& o) {
  pipeline::DetectionsJobOptions& d = o.det;
  d.cameras = o.job.cameras;
  d.ball_diameter_m = o.job.ball_diameter_m;
  d.out = o.job.out;
  d.truth = o.job.truth;
  d.tolerance_s = o.job.pipeline.sync.tolerance_s;
  d.triangulation = o.job.pipeline.triangulation;
  d.eval = o.job.eval;
  d.bundle = o.job.bundle;  // --no-bundle (it was ignored with --detections)
  const pipeline::DetectionsJobResult r = pipeline::RunDetectionsJob(d);
  std::cout << r.Summary() << "\n";
  std::cout << "wrote " << d.out << " (" << r.positions << " rows)"
            << (d.flights.empty() ? "" : ", " + d.flights) << "\n";
  if (r.eval) std::cout << r.eval->Table(o.rows || r.eval->rows.size() <= 40) << "\n";
}

void RunBall(const BallCliOptions& o) {
  const pipeline::BallJobResult r = pipeline::RunBallJob(o.job);
  std::cout << r.summary.ToString() << "\n";
  // The backgrounds some camera's low-contrast candidates asked for (camera_background.h).
  for (size_t c = 0; c < r.backgrounds.size(); ++c) {
    if (r.backgrounds[c].empty()) continue;
    std::cout << o.job.videos[c] << ": " << r.backgrounds[c] << "\n";
  }
  for (size_t c = 0; c < r.frames_notes.size(); ++c) {
    if (!r.frames_notes[c].empty()) {
      std::cout << o.job.videos[c] << ": " << r.frames_notes[c] << "\n";
    }
  }
  if (r.bundle && r.bundle->bundled_flights > 0) {
    std::cout << fmt::format(
        "{} flights refined on the cameras' candidates ({} rows, {:.2f} px RMS{}; --no-bundle: "
        "each frame's own position)\n",
        r.bundle->bundled_flights, r.bundle->bundled_rows, r.bundle->rms_px,
        r.bundle->kept_rows > 0
            ? fmt::format("; {} frames the model does not follow kept", r.bundle->kept_rows)
            : "");
  }
  if (r.bundle && r.bundle->rests.runs > 0) {
    std::cout << r.bundle->rests.Summary("the cameras' candidates") << "\n";
  }
  if (r.bundle && r.bundle->kept_flights > 0) {
    std::cout << fmt::format(
        "{} flights kept frame by frame (the flight model fits the candidates much worse than "
        "the frames: not a free flight)\n",
        r.bundle->kept_flights);
  }
  std::cout << "wrote " << o.job.out << " (" << r.rows_written << " rows)\n";
  if (const std::string w = r.NoPositionWarning(); !w.empty()) {
    std::cerr << "fieldvision: warning: " << w << "\n";
  }
  if (r.eval) std::cout << r.eval->Table(o.rows || r.eval->rows.size() <= 40) << "\n";
  if (!o.draw.dir.empty()) Draw(o);
}

// The outputs checked against the inputs and each other, then the run (videos or detections).
void CheckOutputsAndRun(BallCliOptions& o) {
  const auto inputs = util::PathList(o.job.cameras, o.job.videos, o.job.timestamps, o.job.truth,
                                     o.job.field, o.job.colour, o.det.detections);
  util::CheckOutputPath(o.job.out, inputs);
  util::CheckOutputPath(o.det.flights, util::PathList(inputs, o.job.out), "--flights");
  for (size_t i = 0; i < o.job.detections_out.size(); ++i) {
    std::vector<std::string> others = util::PathList(inputs, o.job.out);
    others.insert(others.end(), o.job.detections_out.begin(),
                  o.job.detections_out.begin() + static_cast<long>(i));
    util::CheckOutputPath(o.job.detections_out[i], others, "--write-detections");
    o.job.detections_out[i] =
        util::ResolveOutputPath(o.job.detections_out[i], "--write-detections");
  }
  o.job.out = util::ResolveOutputPath(o.job.out);  // refuses a device or a folder
  if (!o.det.flights.empty()) o.det.flights = util::ResolveOutputPath(o.det.flights, "--flights");
  if (!o.det.detections.empty()) {
    FV_REQUIRE(o.job.videos.empty(), "ball: give --video or --detections, not both");
    FV_REQUIRE(o.draw.dir.empty(), "ball: --draw needs --video (the frames to draw on)");
    FV_REQUIRE(o.job.detections_out.empty(),
               "ball: --write-detections needs --video (the detections are the input here)");
    RunDetections(o);
    return;
  }
  if (!o.job.timestamps.empty()) o.job.sync = "time";
  RunBall(o);
}

void Setup(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<BallCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "ball", "Place the ball in 3D from 2..N synchronized cameras; writes BALL.csv");
  cmd->add_option("--camera", o->job.cameras, "Camera file (repeat; pairs with --video in order)")
      ->required();
  cmd->add_option("--video", o->job.videos, "Video file or image pattern such as dir/%05d.jpg");
  cmd->add_option("--detections", o->det.detections,
                  "Instead of --video: 2D detections made elsewhere, DET.csv with frame,time_s,u,v "
                  "[,radius_px,score] (repeat; pairs with --camera in order; paired by time)");
  cmd->add_option("--det-sigma", o->det.sigma_px,
                  "With --detections: 1-sigma of a detection's centre in pixels")
      ->check(FiniteRange(0.01, 100))
      ->capture_default_str();
  cmd->add_option("--flights", o->det.flights,
                  "With --detections: also fit the flights and write FLIGHTS.json");
  AddBallDiameterOption(cmd, o->job.ball_diameter_m);
  // What reads and searches frames, refused with --detections (the 2D positions are given).
  CLI::Option_group* frames =
      cmd->add_option_group("Reading frames", "With --video only (not with --detections)");
  AddBallColourOption(frames, o->job.colour);
  AddDetectorOptions(frames, o->job.dnn);
  cmd->add_option("--out", o->job.out, "BALL.csv: frame,time_s,x_m,y_m,z_m,n_cams,err_px")
      ->required();
  cmd->add_option("--write-detections", o->job.detections_out,
                  "Also write each camera's accepted candidates as DET.csv (frame,time_s,u,v,"
                  "radius_px,score: what --detections reads), one per --camera in order");
  cmd->add_option(
      "--draw", o->draw.dir,
      "Also write, into this new (or empty) folder, each camera's video with the ball's 3D "
      "position seen from it at its size and the camera's accepted candidates (NAME.mp4, or .avi "
      "without an H.264 encoder, NAME the camera file's name; frames paired by index; without "
      "--write-detections the candidates go there as NAME_det.csv; a failed drawing leaves "
      "BALL.csv and those files)");
  cmd->add_flag("!--no-bundle", o->job.bundle,
                "Offline: keep each frame's own position instead of refining each flight on the "
                "cameras' candidates at the end");
  cmd->add_option("--truth", o->job.truth, "truth.csv: also print the error table");
  cmd->add_flag("--rows", o->rows, "With --truth: print every frame's error, not only summary");
  frames->add_option("--field", o->job.field,
                     "Field (built-in name or JSON): look for the ball only over it");
  frames
      ->add_option("--sync", o->job.sync,
                   "Pair frames by 'frame' index or by 'time' (the --timestamps CSVs, else the "
                   "container's timestamps)")
      ->capture_default_str();
  frames->add_option(
      "--timestamps", o->job.timestamps,
      "CSV with frame,time_s per video (repeat, one per video); implies --sync time");
  frames
      ->add_option("--fps", o->job.fps,
                   "Frames per second of image sequences, which have no rate of their own (give "
                   "this or --timestamps); a video's own rate must agree with it")
      ->check(FiniteRange(1e-3, 100000.0));
  cmd->add_option("--tolerance", o->job.pipeline.sync.tolerance_s,
                  "With --sync time: frames this close in seconds are combined")
      ->check(FiniteRange(1e-6, 10.0))
      ->capture_default_str();
  AddBackgroundOption(frames, o->job.background);
  frames->add_flag("--live", o->job.live,
                   "Live: play the videos at their frame rate (as cameras deliver) and keep the "
                   "newest frames when fusion falls behind (drops frames)");
  frames
      ->add_option("--max-frames", o->job.pipeline.max_frames,
                   "Stop after this many frames (0: all)")
      ->check(CLI::Range(0LL, 1000000000LL));
  AddFusionOptions(cmd, o->job.pipeline.triangulation);
  AddTrackOptions(frames, o->job.pipeline.track);
  cmd->add_flag("!--no-progress", o->job.pipeline.progress, "Do not show progress");
  cmd->callback([o, cmd, frames] {
    CheckTrackOptions(o->job.pipeline.track);
    FV_REQUIRE(!o->det.detections.empty() ||
                   (cmd->count("--det-sigma") == 0 && cmd->count("--flights") == 0),
               "ball: --det-sigma and --flights apply only with --detections");
    if (!o->det.detections.empty()) {
      for (const CLI::Option* option : frames->get_options()) {
        FV_REQUIRE(option->count() == 0,
                   "ball: {} applies to --video only (with --detections the 2D positions are "
                   "given)",
                   option->get_name());
      }
    }
    if (o->det.detections.empty()) PrepareDraw(*o);
    o->det.own_scores = cmd->count("--min-two-view-score") > 0;
    try {
      CheckOutputsAndRun(*o);
      if (o->draw_dir) o->draw_dir->Keep();
    } catch (...) {
      o->draw_dir.reset();  // the folders it made go while empty
      throw;
    }
  });
}

FV_REGISTER_COMMAND(40, "ball", Setup);

}  // namespace
}  // namespace fv::app
