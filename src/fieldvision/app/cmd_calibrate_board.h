// The board options shared by `calibrate intrinsics` and `calibrate multi` (--board, --cols,
// --rows, --square, --marker, --dictionary) and their calib::BoardSpec, the board fit's options
// they share; the calibrate commands'
// checks of an output file (its folder exists, it is not a device or a folder) before any work.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "fieldvision/app/command.h"
#include "fieldvision/calib/board.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::app {

struct BoardCli {
  std::string board = "chessboard";
  int cols = 0, rows = 0;
  double square_m = 0.0, marker_m = 0.0;
  std::string dictionary = "DICT_4X4_50";

  calib::BoardSpec Spec() const {
    calib::BoardSpec b;
    b.type = calib::ParseBoardType(board);
    b.cols = cols;
    b.rows = rows;
    b.square_m = square_m;
    b.marker_m = marker_m;
    b.dictionary = dictionary;
    return b;
  }
};

inline void AddBoardOptions(CLI::App* cmd, BoardCli& b) {
  cmd->add_option("--board", b.board, "chessboard or charuco")->capture_default_str();
  cmd->add_option("--cols", b.cols, "Chessboard: inner corners per row; ChArUco: squares per row")
      ->required()
      ->check(FiniteRange(2, 200));
  cmd->add_option("--rows", b.rows,
                  "Chessboard: inner corners per column; ChArUco: squares per column")
      ->required()
      ->check(FiniteRange(2, 200));
  cmd->add_option("--square", b.square_m, "Square side in metres (25 mm: 0.025)")
      ->required()
      ->check(FiniteRange(1e-4, 1));
  cmd->add_option("--marker", b.marker_m, "ChArUco marker side in metres (default 0.7 x square)")
      ->check(FiniteRange(1e-4, 1));
  cmd->add_option("--dictionary", b.dictionary, "ChArUco ArUco dictionary")->capture_default_str();
}

// `--k3` (auto, free or zero) is chosen for the 5-number model only: the others decide k3 with
// their own coefficients.
inline void CheckK3Model(const std::string& k3, int num_distortion) {
  FV_REQUIRE(k3 == "auto" || num_distortion == 5,
             "--k3 {} goes with --model 5 (the model of {} numbers decides k3 itself)", k3,
             num_distortion);
}

// The board fit's options that `calibrate intrinsics` and `calibrate multi` share (--model,
// --outlier-factor, --outlier-min-px, --max-frames); `Options` is calib::IntrinsicsOptions or
// calib::MultiOptions.
template <typename Options>
void AddBoardFitOptions(CLI::App* cmd, Options& o) {
  cmd->add_option("--model", o.num_distortion,
                  "Distortion coefficients: 4, 5 (default), 8 (rational), 12, 14")
      ->check(CLI::IsMember({4, 5, 8, 12, 14}))
      ->capture_default_str();
  cmd->add_option("--outlier-factor", o.outlier_factor,
                  "Drop views with RMS above this x the median (and above --outlier-min-px)")
      ->check(FiniteRange(1, 1000))
      ->capture_default_str();
  cmd->add_option("--outlier-min-px", o.outlier_min_px, "See --outlier-factor")
      ->check(FiniteRange(0, 1000))
      ->capture_default_str();
  cmd->add_option("--max-frames", o.source.max_video_frames, "Frames sampled from a video")
      ->check(FiniteRange(1, 100000))
      ->capture_default_str();
}

// Throws (one line naming the option, the path and the fix) when the folder of output file `out`
// does not exist; an empty `out` (option not given) passes.
inline void CheckOutputFolder(const std::string& out, std::string_view what = "--out") {
  if (out.empty()) return;
  const std::filesystem::path folder = std::filesystem::path(out).parent_path();
  FV_REQUIRE(folder.empty() || std::filesystem::is_directory(folder),
             "{} '{}': the folder '{}' does not exist; create it (mkdir -p {}) or write elsewhere",
             what, out, folder.string(), folder.string());
}

// CheckOutputFolder, then the shared output policy's refusal of a device or a folder as the
// output file (io/output_path.h), before any work; an empty `out` passes.
inline void CheckOutputFile(const std::string& out, std::string_view what = "--out") {
  if (out.empty()) return;
  CheckOutputFolder(out, what);
  util::ResolveOutputPath(out, what);
}

}  // namespace fv::app
