// `fieldvision trajectory`: split a ball track into flights, fit them, predict landings, make
// line/goal/basket calls, write FLIGHTS.json, pictures and a smoothed track (trajectory_run.h).

#include <cstdio>
#include <iostream>
#include <memory>

#include "fieldvision/app/command.h"
#include "fieldvision/recon/trajectory_run.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/progress.h"

namespace fv::app {
namespace {

struct TrajectoryCliOptions {
  recon::TrajectoryJob job;
  std::string drag = "auto";
  std::string spin = "auto";
  bool progress = true;
};

void Setup(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<TrajectoryCliOptions>();
  recon::TrajectoryJob& j = o->job;
  CLI::App* c = app.add_subcommand(
      "trajectory", "Split a ball track into flights and fit them (origin, landing, apex, v0)");
  c->add_option("--in", j.in_path,
                "BALL.csv (frame,time_s,x_m,y_m,z_m,n_cams,err_px) or a Timestamp,X,Y,Z CSV; a "
                "folder or a quoted glob ('dir/*.csv') runs every file (batch mode)")
      ->required();
  c->add_option("--out", j.out_path,
                "FLIGHTS.json to write (batch mode: a folder for NAME.json per track and "
                "summary.csv)")
      ->required();
  c->add_option("--ball-diameter", j.ball_diameter_m,
                "Ball diameter in metres (default 0.22; 0.04 for a Timestamp,X,Y,Z file)")
      ->check(FiniteRange(0.001, 1.5));
  c->add_option("--gravity", j.analysis.gravity_mps2, "Gravity in m/s^2 (default 9.81)")
      ->check(FiniteRange(0.01, 1000.0));
  c->add_option("--ground-z", j.analysis.ground_z_m,
                "Height of the bounce surface in metres (default 0)")
      ->check(FiniteRange(-10000.0, 10000.0));
  c->add_option("--drag", o->drag,
                "Quadratic air drag: auto (used when it lowers the residual by > 10 %), on, off")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  c->add_option("--spin", o->spin,
                "Spin (Magnus lift with drag): auto (used when it lowers the BIC by > 10), on, off")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  c->add_option("--ball-mass", j.ball_mass_kg,
                "Ball mass in kg, for the spin in rev/s (default: the standard ball nearest "
                "the diameter: 0.0027 table tennis, 0.0459 golf, 0.0577 tennis, 0.42 futsal, "
                "0.43 football, 0.62 basketball)")
      ->check(FiniteRange(1e-5, 100.0));
  c->add_option("--noise", j.analysis.noise_m,
                "Position noise (1 sigma, metres); default or 0: estimated from the track")
      ->check(FiniteRange(0.0, 100.0));
  c->add_option("--accel-slack", j.accel_slack_mps2,
                "Unmodelled acceleration (drag, spin) allowed before a velocity change counts as "
                "a bounce or hit, m/s^2 (default 10; 25 for a Timestamp,X,Y,Z file)")
      ->check(FiniteRange(0.0, 1000.0));
  c->add_option("--field", j.field,
                "Field (built-in name or JSON) for in/out, goal and basket calls");
  CLI::Option* rule =
      c->add_option("--rule", j.decisions.rule, "In/out rule: auto, football, tennis, basketball")
          ->check(CLI::IsMember({"auto", "football", "tennis", "basketball"}));
  CLI::Option* line = c->add_option(
      "--line", j.decisions.lines, "A named field line to judge each landing against (repeatable)");
  c->add_option("--images", j.images_dir,
                "Folder for pictures: track height over time, top view, side view per flight");
  c->add_option("--smoothed", j.smoothed_path, "Write the Kalman/RTS-smoothed track (BALL.csv)");
  c->add_option("--report", j.report_path, "Write a report JSON (flights, calls, timeline)");
  c->add_option("--predict-fraction", j.predict_fraction,
                "Part of each flight used to predict its landing (default 0.5)")
      ->check(FiniteRange(0.05, 1.0));
  c->add_flag("!--no-progress", o->progress,
              "Do not show progress (shown on a terminal only, while the arcs are fitted)");
  c->callback([o, rule, line, &exit_code] {
    for (const CLI::Option* opt : {rule, line}) {
      FV_REQUIRE(opt->count() == 0 || !o->job.field.empty(),
                 "trajectory: {} needs --field (the calls are made on a field's lines)",
                 opt->get_name());
    }
    o->job.analysis.drag = recon::ParseDragMode(o->drag, "--drag");
    o->job.analysis.spin = recon::ParseDragMode(o->spin, "--spin");
    const auto files = recon::ExpandTrackInputs(o->job.in_path);
    // Nor another output: --smoothed o.json --out o.json wrote the CSV over FLIGHTS.json.
    std::vector<std::string> taken = util::PathList(o->job.in_path, files, o->job.field);
    for (const auto& [out, what] : {std::pair{o->job.out_path, "--out"},
                                    {o->job.smoothed_path, "--smoothed"},
                                    {o->job.report_path, "--report"}}) {
      util::CheckOutputPath(out, taken, what);
      taken.push_back(out);
    }
    if (files.empty()) {
      // Output files, as every writer's: not a device or a folder, in a folder that exists.
      for (const auto& [out, what] : {std::pair{o->job.out_path, "--out"},
                                      {o->job.smoothed_path, "--smoothed"},
                                      {o->job.report_path, "--report"}}) {
        if (!out.empty()) util::ResolveOutputPath(out, what);
      }
      // Progress while the arcs of a long track are fitted (util::Progress: logs stay quiet).
      std::unique_ptr<util::Progress> bar;
      if (o->progress) {
        o->job.analysis.progress = [&bar](size_t done, size_t total) {
          if (!bar) {
            bar = std::make_unique<util::Progress>("trajectory", static_cast<long long>(total),
                                                   "arcs");
          }
          bar->Update(static_cast<long long>(done));
        };
      }
      recon::RunTrajectory(o->job, std::cout);
      o->job.analysis.progress = nullptr;
      if (bar) bar->Finish();
    } else {
      const recon::TrajectoryBatchResult batch =
          recon::RunTrajectoryBatch(o->job, files, std::cout);
      // The others are written; the run still fails, so that a script notices.
      FV_REQUIRE(batch.failed.empty(), "trajectory: {} of {} tracks failed (listed above)",
                 batch.failed.size(), files.size());
    }
    exit_code = 0;
  });
}

FV_REGISTER_COMMAND(50, "trajectory", Setup);

}  // namespace
}  // namespace fv::app
