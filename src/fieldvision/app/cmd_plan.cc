// `fieldvision plan`: coverage, pair angles and expected error of a camera rig over a field, or
// (--optimize) a search for the best rig over allowed mounting places.
#include <iostream>
#include <memory>

#include "fieldvision/app/ball_options.h"
#include "fieldvision/app/command.h"
#include "fieldvision/plan/optimize.h"
#include "fieldvision/plan/plan_run.h"
#include "fieldvision/util/error.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<plan::PlanRunOptions>();
  auto good = std::make_shared<std::vector<double>>();
  CLI::App* cmd = app.add_subcommand(
      "plan",
      "Plan camera placement: on a grid over the field, how many cameras see the ball, the best "
      "pair angle and the expected 3D error; writes coverage.json and colour maps. --optimize "
      "searches the best rig over allowed mounting places and writes rig.json.");
  cmd->add_option("--rig", o->rig_path, "Rig JSON (cameras by position, aim, size, field of view)");
  cmd->add_option("--camera", o->camera_paths, "Camera YAML with a pose (repeat for each)");
  cmd->add_option("--field", o->field,
                  "Built-in field name or field JSON [default: the rig file's field, else "
                  "robocup-msl]");
  cmd->add_option("--out", o->out_dir, "Output folder")->required();
  auto& c = o->coverage;
  cmd->add_option("--step", c.grid_step_m, "Grid cell size in metres")
      ->check(FiniteRange(1e-6, 100))
      ->capture_default_str();
  cmd->add_flag("--surround", c.include_surround, "Grid over the run-off area too");
  AddBallDiameterOption(cmd, c.ball_diameter_m);
  cmd->add_option("--height-above", c.height_above_m,
                  "Second layer of points this far above the ball's height (0: none)")
      ->check(FiniteRange(0, 100))
      ->capture_default_str();
  cmd->add_option("--min-ball-px", c.min_ball_px,
                  "A camera sees the ball only where it is at least this many pixels wide")
      ->check(FiniteRange(0.1, 10000))
      ->capture_default_str();
  cmd->add_option("--margin-px", c.margin_px, "Margin inside the image border")
      ->check(FiniteRange(0, 10000))
      ->capture_default_str();
  cmd->add_option("--noise-px", c.pixel_noise_px, "Detection noise (pixels, 1 sigma per axis)")
      ->check(FiniteRange(0.001, 1000))
      ->capture_default_str();
  cmd->add_option("--good-angle", *good, "Good pair angle range in degrees: MIN MAX (40 120)")
      ->expected(2)
      ->check(FiniteRange(0, 180));
  cmd->add_option("--error-weight", c.error_weight_per_m,
                  "Score = good share - this x worst expected error in metres")
      ->check(FiniteRange(0, 1000))
      ->capture_default_str();
  cmd->add_option("--map-width", o->map.width_px, "Width of the map images in pixels")
      ->check(FiniteRange(200, 8000))
      ->capture_default_str();
  cmd->add_flag("!--no-progress", c.progress, "Do not show progress");
  c.progress = true;
  CLI::Option* optimize =
      cmd->add_flag("--optimize", o->optimize, "Search for the best rig and write DIR/rig.json");
  // The search's options: range-checked, showing their defaults, only with --optimize.
  auto search_option = [&](const std::string& name, auto& value, const std::string& help, double lo,
                           double hi) {
    cmd->add_option(name, value, help)
        ->check(FiniteRange(lo, hi))
        ->capture_default_str()
        ->needs(optimize);
  };
  search_option("--cameras", o->search.num_cameras, "Number of cameras to place (--optimize)", 1,
                32);
  cmd->add_option("--mounts", o->mounts_path,
                  "Mounting places JSON: {\"mounts\": [{\"point\": [x,y,z]} | {\"line\": "
                  "[[x,y,z],[x,y,z]]}]}; default: the perimeter")
      ->needs(optimize);
  search_option("--perimeter-offset", o->perimeter_offset_m,
                "Default mounts: rectangle this far outside the lines (m)", 0, 100);
  search_option("--mount-height", o->mount_height_m, "Default mounts: height (m)", 0.01, 100);
  search_option("--width", o->image_width, "Image width of the cameras to place", 16, 16384);
  search_option("--height", o->image_height, "Image height of the cameras to place", 16, 16384);
  search_option("--hfov", o->hfov_deg, "Horizontal field of view of the cameras to place (deg)", 1,
                179);
  search_option("--search-step", o->search.grid_step_m, "Grid cell size during the search (m)",
                1e-6, 100);
  search_option("--iterations", o->search.iterations, "Annealing steps per restart", 1, 1000000);
  search_option("--restarts", o->search.restarts, "Restarts (the first from an even spread)", 1,
                100);
  cmd->add_option("--seed", o->search.seed, "Random seed of the search")
      ->check(Seed())
      ->capture_default_str()
      ->needs(optimize);
  cmd->callback([o, good, &exit_code] {
    if (good->size() == 2) {
      FV_REQUIRE((*good)[0] <= (*good)[1], "--good-angle MIN MAX: MIN ({}) is above MAX ({})",
                 (*good)[0], (*good)[1]);
      o->coverage.good_angle_min_deg = (*good)[0];
      o->coverage.good_angle_max_deg = (*good)[1];
    }
    o->search.progress = o->coverage.progress;
    // A bad mounts file fails before RunPlan creates the output folder.
    if (!o->mounts_path.empty()) plan::ReadMountsJson(o->mounts_path);
    const plan::PlanRunResult r = plan::RunPlan(*o);
    std::cout << r.summary;
    exit_code = 0;
  });
}

FV_REGISTER_COMMAND(60, "plan", Setup);

}  // namespace
}  // namespace fv::app
