// `fieldvision players`: detect and track people in a video, positions on the field (TRACKS.csv).
#include <filesystem>
#include <iostream>
#include <optional>

#include <fmt/format.h>

#include "fieldvision/app/command.h"
#include "fieldvision/camera/camera_io.h"
#include "fieldvision/field/field.h"
#include "fieldvision/io/video_writer.h"
#include "fieldvision/track/edits.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/track/motion_file.h"
#include "fieldvision/track/overlay.h"
#include "fieldvision/track/players.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::app {
namespace {

struct PlayersCli {
  std::string camera, video, out, field, onnx, draw, mot_out;
  track::PlayersOptions o;
  track::OverlayOptions overlay;  // --draw
};

void RunPlayersCommand(const PlayersCli& c) {
  FV_REQUIRE(c.overlay.legend || !c.draw.empty(), "players: --no-legend applies only with --draw");
  std::optional<camera::Camera> camera;
  if (!c.camera.empty()) camera = camera::ReadCameraYaml(c.camera);
  std::optional<field::FieldModel> field;
  if (!c.field.empty()) field = field::LoadField(c.field);
  FV_REQUIRE(!field || (camera && camera->has_pose),
             "--field needs --camera with a pose (the field area is found through it)");
  track::PlayersOptions o = c.o;
  if (!c.onnx.empty()) {
    o.detector.kind = "onnx";
    o.detector.model_path = c.onnx;
  }
  const track::PlayersResult r =
      track::RunPlayers(c.video, camera ? &*camera : nullptr, field ? &*field : nullptr, o);
  track::WriteTracksCsv(r.rows, c.out);
  if (!c.mot_out.empty()) track::WriteMotChallenge(r.rows, c.mot_out);
  track::Roster roster;
  roster.team_of = r.team_of;
  const std::string roster_done = track::SaveRosterFor(c.out, roster);
  if (!roster_done.empty()) std::cout << roster_done << "\n";
  const std::string motion_done = track::SaveMotionFor(c.out, r.canvas ? &*r.canvas : nullptr);
  if (!motion_done.empty()) std::cout << motion_done << "\n";
  std::cout << r.Summary() << "\nwrote " << c.out << (c.mot_out.empty() ? "" : " and " + c.mot_out)
            << "\n";
  if (r.rows.empty()) {
    std::cerr << "fieldvision: warning: no tracks"
              << (r.dropped_tracks > 0
                      ? fmt::format(" ({} dropped as shorter than {} frames: lower "
                                    "--min-track-frames)",
                                    r.dropped_tracks, r.min_track_frames)
                      : "")
              << "\n";
  }
  if (r.time.time_s.empty()) {
    std::cerr << "fieldvision: warning: time_s left empty: " << r.time.source << "\n";
  }
  if (r.view_drift && r.view_drift->moved) {
    const track::ViewDriftStats& v = *r.view_drift;
    std::cerr << "fieldvision: warning: "
              << (v.mostly_unmatched
                      ? fmt::format("{} of {} frames checked could not be matched to the first "
                                    "(the view left it?)",
                                    v.unmatched, v.checked)
                      : fmt::format("the view moved by up to {:.0f} px from the first frame's "
                                    "(frame {})",
                                    v.max_shift_px, v.max_frame + 1))
              << ": the positions assume a still camera; for a camera that sways, pans or was "
                 "knocked, run with --moving-camera\n";
  }
  // Frames not registered take the view the camera's motion predicts: as good as that guess.
  if (r.camera_motion && r.camera_motion->lost > 0.1 * r.frames) {
    std::cerr << "fieldvision: warning: " << r.camera_motion->lost << " of " << r.frames
              << " frames could not be matched to the first or the last registered one (too "
                 "little texture off the people?): their positions assume the camera kept moving "
                 "as before\n";
  }
  // People the view turned or moved to beyond the canvas have no canvas pixels to be tracked on.
  if (r.beyond_canvas > 0) {
    std::cerr << "fieldvision: warning: " << r.beyond_canvas << " detections in "
              << r.beyond_canvas_frames << " frames (the first in frame " << r.first_beyond_canvas
              << ") lay beyond the canvas (the first frame's view widened by --canvas-margin "
              << c.o.camera_motion.canvas_margin
              << " image widths each side) and were left out: raise --canvas-margin, or start the "
                 "video aimed at the middle of what it pans over (a flat canvas never reaches 90 "
                 "degrees from the first view)\n";
  }
  if (!c.draw.empty()) {
    // Field lines need a posed camera; without a field file the camera's own field is unknown.
    track::TrackOverlay overlay(r.rows, r.team_of, {}, camera ? &*camera : nullptr,
                                field ? &*field : nullptr, c.overlay);
    // A moving camera's lines move with each frame.
    if (r.canvas) overlay.SetCameraMotion(*r.canvas);
    const track::DrawVideoResult d =
        track::DrawTracksVideo(c.video, c.draw, overlay, c.o.fps, c.o.max_frames);
    std::cout << d.Summary() << "\n";
  }
}

// --draw and how it draws.
void AddDrawOptions(CLI::App* cmd, PlayersCli& c) {
  cmd->add_option("--draw", c.draw,
                  "Also write the video with boxes, ids, team colours, trails and (with a posed "
                  "camera and --field) the field lines: H.264 .mp4, or MJPG .avi where OpenCV has "
                  "no H.264 encoder");
  cmd->add_flag("!--no-legend", c.overlay.legend,
                "With --draw: leave out the legend in the bottom-left corner (teams, boxes, "
                "trails, lines)");
}

// The offline passes after the tracker (gaps, tracklets, smoothing, hidden feet) and a moving
// camera.
void AddTrackingPassOptions(CLI::App* cmd, PlayersCli& c) {
  cmd->add_option("--interpolate", c.o.interpolate_max_gap,
                  "Fill track gaps up to this many frames (0: off)")
      ->check(FiniteRange(0, 100000))
      ->capture_default_str();
  cmd->add_option("--stitch-gap", c.o.stitch.max_gap_s,
                  "Join tracklets of one person across gaps up to this many seconds (0: off)")
      ->check(FiniteRange(0, 3600))
      ->capture_default_str();
  cmd->add_option("--stitch-appearance", c.o.stitch.max_appearance_distance,
                  "Largest torso-colour distance (Bhattacharyya, 0..1) for joining tracklets")
      ->check(FiniteRange(0, 1))
      ->capture_default_str();
  cmd->add_option("--smooth-accel", c.o.smooth.accel_sigma_mps2,
                  "Field-position smoothing (Kalman + RTS): players' acceleration sigma in m/s^2 "
                  "(smaller: smoother)")
      ->check(FiniteRange(0.01, 1000))
      ->capture_default_str();
  cmd->add_flag("!--no-smooth", c.o.smooth.enabled, "Do not smooth the field positions");
  cmd->add_flag("!--no-hidden-feet", c.o.hidden_feet.enabled,
                "Keep the foot point of every box: do not move the feet of a person whose legs "
                "are hidden (a box whose top lies under 0.85 of their height above its foot) to "
                "below the head at their height");
  CLI::Option* moving = cmd->add_flag(
      "--moving-camera", c.o.moving_camera,
      "The camera sways, turns, pans or drifts (a phone held by hand or following "
      "play, a drone): each frame is registered to the first (optical flow and ORB "
      "features off the people, a homography), where the camera file's pose holds, and people are "
      "tracked and placed on that view widened by --canvas-margin (writes "
      "TRACKS.csv.motion.json, read by tracks draw)");
  cmd->add_flag("!--no-line-anchor", c.o.hold_to_lines,
                "With --moving-camera: do not hold the views to the painted field lines (with a "
                "posed camera file and a field with lines, each keyframe's view is fitted to the "
                "lines it sees, which stops the registration's drift; the fit turns the camera "
                "about the camera file's centre, or with --moving-centre refits its whole pose)")
      ->needs(moving);
  cmd->add_flag("--moving-centre", c.o.moving_centre,
                "With --moving-camera: the camera moves as well as turns (a drone, a camera "
                "carried along the side line): frames are registered on the ground alone (the "
                "field and its surround, not the stands) and the field lines refit each frame's "
                "whole pose; needs --field and a posed camera file")
      ->needs(moving);
  cmd->add_option("--canvas-margin", c.o.camera_motion.canvas_margin,
                  "With --moving-camera: how many image widths (heights) beyond the first view "
                  "people are tracked on each side")
      ->check(FiniteRange(0, 10))
      ->capture_default_str()
      ->needs(moving);
}

void Setup(CLI::App& app, int& exit_code) {
  auto c = std::make_shared<PlayersCli>();
  CLI::App* cmd = app.add_subcommand(
      "players", "Detect and track people in a video; positions on the field (TRACKS.csv)");
  cmd->add_option("--camera", c->camera,
                  "Camera file (CAM.yaml) of the video; without one (or without a pose) only boxes "
                  "are tracked and x_m,y_m stay empty");
  cmd->add_option("--video", c->video, "Video file or image pattern (dir/%05d.jpg)")->required();
  cmd->add_option(
         "--out", c->out,
         "TRACKS.csv: frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s (frames "
         "from 1 as MOTChallenge; time from the video's timestamps, else its frame rate)")
      ->required();
  cmd->add_option("--field", c->field,
                  "Field (built-in name or JSON): keep only people on it plus --margin");
  CLI::Option* margin =
      cmd->add_option("--margin", c->o.field_margin_m, "Metres around the field still accepted")
          ->check(FiniteRange(0, 100))
          ->capture_default_str();
  cmd->add_option("--detector", c->o.detector.kind, "nanodet (default), hog, motion or onnx")
      ->check(CLI::IsMember({"nanodet", "hog", "motion", "onnx"}));
  cmd->add_option("--onnx", c->onnx, "A YOLO-style ONNX model of your own (sets --detector onnx)");
  cmd->add_option("--detections", c->o.detections_in,
                  "Read detections (MOTChallenge det.txt: frame,-1,x,y,w,h,score; 1-based "
                  "frames) instead of running a detector");
  cmd->add_option("--save-detections", c->o.detections_out,
                  "Also write the detections (after filtering) as det.txt for --detections");
  cmd->add_option("--model", c->o.detector.model_path,
                  "NanoDet model (default: BUILD/models/nanodet.onnx from make build)");
  cmd->add_option("--input-width", c->o.detector.input_width,
                  "Network input width in pixels (multiple of 32; smaller is faster)")
      ->check(NetworkWidth())
      ->capture_default_str();
  cmd->add_option("--score", c->o.detector.score_threshold, "Lowest detection score kept")
      ->check(FiniteRange(0, 1))
      ->capture_default_str();
  cmd->add_option("--min-height", c->o.detector.min_height_px,
                  "Ignore people shorter than this in pixels (far outside the area of interest)")
      ->check(FiniteRange(0, 100000))
      ->capture_default_str();
  cmd->add_option("--threads", c->o.detector.threads, "OpenCV threads (0: all cores)")
      ->check(FiniteRange(0, 256));
  cmd->add_option("--sot", c->o.tracker.sot,
                  "Single-target tracker through missed detections: none, csrt, kcf, mosse")
      ->check(CLI::IsMember({"none", "csrt", "kcf", "mosse"}));
  cmd->add_option("--max-lost", c->o.tracker.max_lost_frames,
                  "Frames a lost track is kept to be re-found")
      ->check(FiniteRange(0, 100000))
      ->capture_default_str();
  cmd->add_option("--max-frames", c->o.max_frames, "Process at most this many frames (0: all)")
      ->check(FiniteRange(0, 1e9));
  cmd->add_option("--fps", c->o.fps,
                  "Override the video's time: frame i at i / FPS seconds (default: the video's "
                  "timestamps, else its frame rate)")
      ->check(FiniteRange(0.01, 10000));
  cmd->add_option("--min-track-frames", c->o.min_track_frames,
                  "Drop tracks seen in fewer frames (0: keep all; on a clip shorter than twice "
                  "this, half the clip); the summary says how many were dropped")
      ->check(FiniteRange(0, 1000000))
      ->capture_default_str();
  AddDrawOptions(cmd, *c);
  cmd->add_option("--mot-out", c->mot_out,
                  "Also write the tracks as a MOTChallenge results file (no header, "
                  "frame,id,left,top,w,h,conf,-1,-1,-1) for TrackEval / py-motmetrics");
  AddTrackingPassOptions(cmd, *c);
  cmd->add_flag("--teams", c->o.teams,
                "Split tracks into two teams by shirt colour (writes TRACKS.csv.teams.csv)");
  cmd->add_flag("!--no-progress", c->o.progress, "No progress line");
  cmd->callback([c, margin] {
    FV_REQUIRE(margin->count() == 0 || !c->field.empty(),
               "players: --margin needs --field (it widens the field area people are kept in)");
    // An empty detections file is a failed export, not a video without people: refuse it rather
    // than write a TRACKS.csv without rows.
    std::error_code ec;
    FV_REQUIRE(c->o.detections_in.empty() ||
                   !std::filesystem::is_regular_file(c->o.detections_in, ec) ||
                   std::filesystem::file_size(c->o.detections_in, ec) > 0,
               "players: --detections '{}' is empty (a det.txt has a row per detection: "
               "frame,-1,x,y,w,h,score)",
               c->o.detections_in);
    const auto inputs = util::PathList(c->camera, c->video, c->field, c->onnx, c->o.detections_in);
    util::CheckOutputPath(c->out, inputs);
    for (const auto& [out, what] :
         {std::pair{c->mot_out, "--mot-out"}, {c->o.detections_out, "--save-detections"}}) {
      util::CheckOutputPath(out, util::PathList(inputs, c->out), what);
    }
    util::CheckOutputPath(track::RosterPathFor(c->out), inputs, "--out's teams file");
    util::CheckOutputPath(track::MotionPathFor(c->out), inputs, "--out's camera motion file");
    if (!c->draw.empty()) io::CheckVideoOutput(c->draw, util::PathList(inputs, c->out), "--draw");
    // A device, a folder or a missing folder as an output is refused before the run.
    for (const auto& [out, what] : {std::pair{c->out, "--out"},
                                    {c->mot_out, "--mot-out"},
                                    {c->o.detections_out, "--save-detections"}}) {
      if (!out.empty()) util::ResolveOutputPath(out, what);
    }
    try {
      RunPlayersCommand(*c);
    } catch (const Error& e) {
      // RunPlayers names the camera by its name (camera::FitCameraToFrames): add its file.
      const std::string what = e.what();
      if (!c->camera.empty() && what.rfind("camera '", 0) == 0 &&
          what.find(" images but video ") != std::string::npos) {
        Throw("{}: {}", c->camera, what);
      }
      throw;
    }
  });
}

FV_REGISTER_COMMAND(70, "players", Setup);

}  // namespace
}  // namespace fv::app
