// `fieldvision eval ball`: the error table of a ball track against ground truth
// (recon/ball_eval.h), matched by frame.
#include <iostream>
#include <memory>

#include "fieldvision/app/command.h"
#include "fieldvision/app/input_checks.h"
#include "fieldvision/recon/ball_eval.h"
#include "fieldvision/util/error.h"

namespace fv::app {
namespace {

struct EvalBallCliOptions {
  std::string truth;
  std::string est;
  bool rows = false;
  recon::BallEvalOptions eval;
};

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "eval");
  auto o = std::make_shared<EvalBallCliOptions>();
  CLI::App* cmd = group->add_subcommand("ball", "Error table of a ball track against truth");
  cmd->add_option("--truth", o->truth, "Truth CSV: frame,x_m,y_m,z_m[,time_s,n_cams]")->required();
  cmd->add_option("--est", o->est, "Estimate CSV (BALL.csv): frame,x_m,y_m,z_m[,...]")->required();
  cmd->add_flag("--rows", o->rows, "Print every frame's error (default: when <= 40 frames)");
  cmd->add_option("--min-cams", o->eval.min_truth_cams,
                  "Truth frames seen by at least this many cameras count for the found rate")
      ->check(FiniteRange(0, 1000))
      ->capture_default_str();
  cmd->add_option("--outlier", o->eval.outlier_m, "Estimates further off (metres) are false")
      ->check(FiniteRange(1e-6, 1e4))
      ->capture_default_str();
  cmd->callback([o] {
    const util::CsvTable truth = util::CsvTable::Read(o->truth), est = util::CsvTable::Read(o->est);
    for (const util::CsvTable* t : {&truth, &est}) {
      t->Require({"frame", "x_m", "y_m", "z_m"});
      recon::CheckBallTrackRanges(*t);
    }
    const recon::BallEvalResult r = recon::EvaluateBall(truth, est, o->eval);
    // Nothing matched: no error to report (a mean of 0 mm would read as perfect).
    FV_REQUIRE(!r.rows.empty(),
               "eval ball: no frame of '{}' ({} rows) is a frame of '{}' ({} rows): nothing to "
               "compare (are both numbered from the same first frame?)",
               o->est, r.estimates, o->truth, r.truth_frames);
    std::cout << r.Table(o->rows || r.rows.size() <= 40) << "\n";
  });
}

FV_REGISTER_COMMAND(80, "eval ball", Setup);

}  // namespace
}  // namespace fv::app
