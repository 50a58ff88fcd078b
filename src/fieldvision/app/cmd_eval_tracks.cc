// `fieldvision eval tracks`: MOTA, MOTP, IDF1, HOTA of TRACKS.csv against ground truth; and
// `fieldvision eval import-pets`: PETS CVML annotations -> MOT CSV.
#include <algorithm>
#include <fstream>
#include <iostream>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "fieldvision/app/command.h"
#include "fieldvision/app/input_checks.h"
#include "fieldvision/camera/camera_io.h"
#include "fieldvision/stats/stats.h"
#include "fieldvision/track/bytetrack.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/track/motion_file.h"
#include "fieldvision/track/pets.h"
#include "fieldvision/track/position_eval.h"
#include "fieldvision/track/synth_truth.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

namespace fv::app {
namespace {

struct EvalTracksCli {
  std::string gt, est, json, camera, gt_cam;
  double foot_offset_m = track::TrackerOptions{}.foot_offset_m;
  track::MotOptions o;
};

bool AnyPosition(const std::vector<track::TrackRow>& rows) {
  for (const auto& r : rows) {
    if (r.x_m && r.y_m) return true;
  }
  return false;
}

std::vector<track::TrackRow> ReadGt(const std::string& path, const std::string& cam) {
  if (util::EndsWith(util::ToLower(path), ".xml")) return track::ReadPetsCvml(path);
  if (track::IsSynthPeopleTruth(path)) return track::ReadSynthPeopleTruth(path, cam);
  FV_REQUIRE(cam.empty(), "--gt-cam is for synth's players_2d.csv; '{}' is not one", path);
  return track::ReadTracksCsv(path);
}

// The posed camera of --camera, checked before any scoring; none without the option.
std::optional<camera::Camera> ReadPositionCamera(const EvalTracksCli& c,
                                                 const std::vector<track::TrackRow>& est) {
  if (c.camera.empty()) return std::nullopt;
  camera::Camera cam = camera::ReadCameraYaml(c.camera);
  FV_REQUIRE(cam.has_pose, "{}: the camera has no pose (field positions need one)", c.camera);
  FV_REQUIRE(AnyPosition(est),
             "--camera given but the estimate '{}' has no field positions (x_m, y_m)", c.est);
  return cam;
}

// Field-position errors when the estimate has positions and the ground truth has them (placed by
// the camera where given).
std::optional<track::PositionErrors> ScorePositions(const EvalTracksCli& c,
                                                    const std::vector<track::TrackRow>& gt,
                                                    const std::vector<track::TrackRow>& est) {
  if (!AnyPosition(est) || !AnyPosition(gt)) return std::nullopt;
  track::PositionEvalOptions po;
  po.iou_threshold = c.o.iou_threshold;
  po.frame_offset = c.o.frame_offset;
  return track::EvaluatePositions(gt, est, po);
}

// The coach's numbers (`stats`: distance covered, top speed) of the estimate and of the ground
// truth's positions, both timed at the estimate's frame rate (the ground truth often has no time).
struct CoachNumbers {
  double fps = 0;
  double est_distance_m = 0, gt_distance_m = 0;
  double est_top_speed_mps = 0, gt_top_speed_mps = 0;
  std::string Summary() const {
    return fmt::format(
        "coach's numbers (stats, {:.2f} frames/s): distance over everyone {:.0f} m against the "
        "ground truth's {:.0f} m ({:+.1f} %), top speed {:.2f} m/s against {:.2f} m/s",
        fps, est_distance_m, gt_distance_m,
        gt_distance_m > 0 ? 100.0 * (est_distance_m / gt_distance_m - 1.0) : 0.0, est_top_speed_mps,
        gt_top_speed_mps);
  }
  nlohmann::json ToJson() const {
    return {{"fps", fps},
            {"distance_m", est_distance_m},
            {"gt_distance_m", gt_distance_m},
            {"top_speed_mps", est_top_speed_mps},
            {"gt_top_speed_mps", gt_top_speed_mps}};
  }
};

std::optional<CoachNumbers> CompareCoachNumbers(const std::vector<track::TrackRow>& gt,
                                                const std::vector<track::TrackRow>& est) {
  for (const auto& r : est) {
    if (!r.time_s) return std::nullopt;  // a MOTChallenge file: no time to give speeds
  }
  CoachNumbers n;
  n.fps = stats::FrameRateOfRows(est);
  if (!(n.fps > 0)) return std::nullopt;
  stats::StatsOptions so;
  so.fps = n.fps;
  so.write_video = false;
  std::vector<track::TrackRow> gt_placed;
  for (const auto& r : gt) {
    if (r.x_m && r.y_m) gt_placed.push_back(r);
  }
  const stats::StatsResult e = stats::ComputeStats(est, so), g = stats::ComputeStats(gt_placed, so);
  for (const auto& p : e.players) {
    n.est_distance_m += p.distance_m;
    n.est_top_speed_mps = std::max(n.est_top_speed_mps, p.top_speed_mps);
  }
  for (const auto& p : g.players) {
    n.gt_distance_m += p.distance_m;
    n.gt_top_speed_mps = std::max(n.gt_top_speed_mps, p.top_speed_mps);
  }
  return n;
}

void RunEvalTracks(const EvalTracksCli& c) {
  const auto gt = ReadGt(c.gt, c.gt_cam);
  const auto est = track::ReadTracksCsv(c.est);
  // Nothing to score is an error, not a table of zeros.
  FV_REQUIRE(!gt.empty(), "ground truth '{}' has no boxes", c.gt);
  FV_REQUIRE(!est.empty(), "estimate '{}' has no boxes", c.est);
  const std::optional<camera::Camera> cam = ReadPositionCamera(c, est);
  const track::MotMetrics m = [&] {
    try {
      return track::EvaluateMot(gt, est, c.o);
    } catch (const Error& e) {
      // EvaluateMot names its inputs "ground truth" and "estimate": add the file.
      const std::string what = e.what();
      if (util::StartsWith(what, "ground truth:")) Throw("{}: {}", c.gt, what);
      if (util::StartsWith(what, "estimate:")) Throw("{}: {}", c.est, what);
      throw;
    }
  }();
  std::cout << m.Summary() << "\n" << m.preprocessing.Summary() << "\n";
  // Field positions and the coach's numbers over the frames the metrics scored (--est-frames,
  // --all-frames).
  std::vector<track::TrackRow> placed = gt;
  std::vector<track::TrackRow> scored = est;
  m.preprocessing.ClipAsScored(placed, scored, c.o.frame_offset);
  // A moving camera's tracks (players --moving-camera): the ground truth's feet through the
  // camera's motion saved beside them.
  const auto canvas =
      cam ? track::ReadMotionFor(c.est, &*cam, fmt::format("camera file '{}'", c.camera))
          : std::nullopt;
  if (canvas) {
    track::PlaceFeet(*canvas, c.foot_offset_m, &placed);
    std::cout << "ground truth placed through the camera's motion in "
              << track::MotionPathFor(c.est) << "\n";
  } else if (cam) {
    track::PlaceFeet(*cam, c.foot_offset_m, &placed);
  }
  const auto positions = ScorePositions(c, placed, scored);
  if (positions) std::cout << positions->Summary() << "\n";
  const auto coach = positions ? CompareCoachNumbers(placed, scored) : std::nullopt;
  if (coach) std::cout << coach->Summary() << "\n";
  if (!c.json.empty()) {
    nlohmann::json j = nlohmann::json::parse(m.ToJson());
    if (positions) j["positions"] = nlohmann::json::parse(positions->ToJson());
    if (coach) j["coach"] = coach->ToJson();
    util::AtomicWrite(
        c.json,
        [&](const std::string& tmp) {
          std::ofstream out(tmp);
          FV_REQUIRE(out.good(), "cannot write '{}'", c.json);
          out << j.dump(2) << "\n";
          out.close();
          FV_REQUIRE(!out.fail(), "cannot write '{}'", c.json);
        },
        "--json");
  }
}

struct ImportPetsCli {
  std::string xml, out;
};

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "eval");
  auto c = std::make_shared<EvalTracksCli>();
  CLI::App* cmd = group->add_subcommand(
      "tracks", "MOTA, MOTP, IDF1 and HOTA of player tracks against ground truth (MOTChallenge)");
  cmd->add_option("--gt", c->gt,
                  "Ground truth: MOT gt.txt (MOT17 rules applied), TRACKS.csv, a PETS CVML .xml "
                  "(frames numbered from 1), or synth's players_2d.csv (people at least 20 % "
                  "visible, positions from players.csv beside it)")
      ->required();
  cmd->add_option("--gt-cam", c->gt_cam,
                  "With synth's players_2d.csv of several cameras: the camera whose truth is "
                  "scored");
  cmd->add_option("--est", c->est, "Estimated TRACKS.csv or MOTChallenge results file")->required();
  cmd->add_option("--iou", c->o.iou_threshold, "IoU needed for a match (MOTChallenge: 0.5)")
      ->check(FiniteRange(1e-6, 1));
  cmd->add_option("--frame-offset", c->o.frame_offset,
                  "Add this to the estimate's frame numbers (e.g. 1 for a 0-based file against "
                  "MOT ground truth); the output warns when another offset fits far better")
      ->check(FiniteRange(-1000000, 1000000));
  cmd->add_flag("!--no-mot17-rules", c->o.mot17_rules,
                "Score every ground-truth row (default, for MOT16/17/20 ground truth with classes: "
                "drop conf-0 and non-pedestrian rows and estimates on distractors, as TrackEval)");
  cmd->add_flag("!--all-frames", c->o.clip_to_gt_frames,
                "Also count estimated rows in frames outside the ground truth's first..last frame "
                "(default: left out)");
  cmd->add_flag("--est-frames", c->o.clip_to_est_frames,
                "Score only the frames from the estimate's first to its last (an estimate of a "
                "clip; default: ground truth outside them counts as misses, and a note says so)");
  cmd->add_option("--json", c->json, "Also write the metrics as JSON");
  cmd->add_option("--camera", c->camera,
                  "Posed camera of the video: the ground truth's boxes get field positions (their "
                  "foot points, as `players` maps its boxes; rows with positions keep them), and "
                  "the estimate's x_m, y_m are scored against them (without it: when both files "
                  "have positions)");
  cmd->add_option("--foot-offset", c->foot_offset_m,
                  "With --camera: the foot point moved this far from the camera (metres, as "
                  "`players`)")
      ->capture_default_str()
      ->check(FiniteRange(0, 2))
      ->needs("--camera");
  cmd->callback([c] {
    util::CheckOutputPath(c->json, util::PathList(c->gt, c->est, c->camera), "--json");
    if (!c->json.empty()) util::ResolveOutputPath(c->json, "--json");
    RunEvalTracks(*c);
  });

  auto p = std::make_shared<ImportPetsCli>();
  CLI::App* imp =
      group->add_subcommand("import-pets", "Convert PETS 2009 CVML annotations to MOT CSV");
  imp->add_option("--xml", p->xml, "PETS CVML annotation file (e.g. PETS2009-S2L1.xml)")
      ->required();
  imp->add_option("--out", p->out, "MOT CSV (TRACKS.csv layout)")->required();
  imp->callback([p] {
    util::CheckOutputPath(p->out, {p->xml});
    util::ResolveOutputPath(p->out);  // not a device, a folder or in a missing folder
    const auto rows = track::ReadPetsCvml(p->xml);
    track::WriteTracksCsv(rows, p->out);
    std::cout << "wrote " << rows.size() << " boxes to " << p->out << "\n";
  });
}

FV_REGISTER_COMMAND(81, "eval tracks", Setup);

}  // namespace
}  // namespace fv::app
