// The ball options that several subcommands declare alike: --ball-diameter (ball, node, fuse,
// detect, plan), --color (ball, node, detect, eval detect) and the fusion's --inlier-px, --ground
// and --no-weak (ball, fuse; recon/triangulation.h), the tracking window's --whole-frames,
// --full-scan-every, --scan-bands, --guided-frames, --unconfirmed-scan-every and
// --hidden-scan-every (ball, node; pipeline/camera_stage.h).
#pragma once

#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "fieldvision/app/command.h"
#include "fieldvision/detect/colour.h"
#include "fieldvision/pipeline/camera_stage.h"
#include "fieldvision/recon/triangulation.h"
#include "fieldvision/util/error.h"

namespace fv::app {

inline void AddBallDiameterOption(CLI::App* cmd, double& diameter_m) {
  cmd->add_option("--ball-diameter", diameter_m, "Ball diameter in metres")
      ->check(FiniteRange(0.01, 1.5))
      ->capture_default_str();
}

inline void AddBallColourOption(CLI::App* cmd, std::string& colour) {
  cmd->add_option("--color,--colour", colour,
                  fmt::format("Colour preset ({}) or colour file from `color learn`",
                              fmt::join(detect::ColourPresetNames(), ", ")))
      ->capture_default_str();
}

inline void AddFusionOptions(CLI::App* cmd, recon::TriangulationOptions& t) {
  cmd->add_option("--inlier-px", t.inlier_threshold_px,
                  "A camera agrees when it sees the ball within this many pixels")
      ->check(FiniteRange(0.01, 1000.0))
      ->capture_default_str();
  cmd->add_option("--max-radius-ratio", t.max_radius_ratio,
                  "A camera agrees only when its ball's radius is within this factor of the one "
                  "expected at the point (0: any radius)")
      ->check(FiniteRange(0.0, 0.0) | FiniteRange(1.01, 100.0))
      ->capture_default_str();
  cmd->add_option("--max-larger-radius-ratio", t.max_larger_radius_ratio,
                  "A camera whose ball's radius is more than this factor larger than the one "
                  "expected at the point does not agree (a circle that took in something beside "
                  "the ball; 0: --max-radius-ratio alone)")
      ->check(FiniteRange(0.0, 0.0) | FiniteRange(1.01, 100.0))
      ->capture_default_str();
  cmd->add_option("--score-radius-sigma", t.score_radius_sigma,
                  "Between sets of equally many cameras, each camera's score counts weighted by "
                  "how well its ball's radius fits the point (this spread of the log ratio; 0: "
                  "scores alone)")
      ->check(FiniteRange(0.0, 10.0))
      ->capture_default_str();
  cmd->add_option("--min-two-view-score", t.min_two_view_score,
                  "Two cameras alone whose detector scores (weighted as above) total less are no "
                  "ball unless it is expected there (0: off; with --detections only when given: "
                  "scores made elsewhere have no known scale)")
      ->check(FiniteRange(0.0, 100.0))
      ->capture_default_str();
  cmd->add_option("--still-max-change", t.still_max_change,
                  "Two cameras alone, one seeing a thing that came into view and the other a "
                  "thing that was there all along (its disc differs from the camera's "
                  "background on at most this share), are no ball (0: off)")
      ->check(FiniteRange(0.0, 0.69))
      ->capture_default_str();
  cmd->add_flag("--ground", t.single_camera_ground,
                "Seen by one camera only: place the ball on the ground (a 2D position, n_cams 1)");
  cmd->add_flag("!--no-weak", t.use_weak,
                "Never use candidates that failed a shape check to complete a position");
}

// The tracking options together (each checks its own range): in the options' names.
inline void CheckTrackOptions(const pipeline::BallTrackOptions& t) {
  FV_REQUIRE(t.scan_bands <= t.full_scan_every,
             "--scan-bands ({}) must not exceed --full-scan-every ({})", t.scan_bands,
             t.full_scan_every);
}

inline void AddTrackOptions(CLI::App* cmd, pipeline::BallTrackOptions& t) {
  cmd->add_flag("!--whole-frames", t.enabled, "Search every frame whole (no tracking window)");
  cmd->add_option("--full-scan-every", t.full_scan_every,
                  "While tracking, search the whole frame for other balls every N frames")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--scan-bands", t.scan_bands,
                  "Split that search into N bands of rows, one a frame (1..--full-scan-every): a "
                  "lower peak of work per frame, a little more work on average")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--guided-frames", t.max_guided_frames,
                  "Where the search finds no ball at the tracked ball's expected place, fit one "
                  "there with its size, for at most N frames in a row (0: never)")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  cmd->add_option("--unconfirmed-scan-every", t.unconfirmed_scan_every,
                  "While the cameras together have no position for the ball, each tracking "
                  "camera searches the whole frame every N frames (0: only every "
                  "--full-scan-every), so that a track on a still thing gives way to the ball "
                  "(a camera node: once the fusion node tells of frames without one)")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  cmd->add_option("--hidden-scan-every", t.hidden_scan_every,
                  "While the cameras together see the ball and this camera finds none where "
                  "they expect it (hidden from it), search its whole frame only every N frames "
                  "after the first (0 or 1: every frame)")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
}

}  // namespace fv::app
