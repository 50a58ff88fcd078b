// The `--detector auto|colour|dnn|both` option group (detect/dnn_ball.h), shared by `detect`,
// `eval detect` and `ball`.
#pragma once

#include <functional>
#include <iostream>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "fieldvision/app/command.h"
#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/dnn_ball.h"
#include "fieldvision/dnn/nanodet.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/util/error.h"

namespace fv::app {

// The colour detector's scanline step (`detect`, `eval detect`).
inline void AddScanStepOption(CLI::App* cmd, detect::BallDetectorOptions& o) {
  cmd->add_option("--step", o.scan_step_px,
                  "Scanline step in pixels (1: every pixel, finds balls with only a few pixels "
                  "of their colour, and more fragments)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
}

// The colour detector's radius limits, small-ball stage, off-field score and lit-part check
// (`detect`, `eval detect`).
inline void AddBallSizeOptions(CLI::App* cmd, detect::BallDetectorOptions& o) {
  cmd->add_option("--min-radius", o.min_radius_px, "Smallest ball radius in pixels")
      ->check(FiniteRange(0.1, 10000.0))
      ->capture_default_str();
  cmd->add_option("--max-radius", o.max_radius_px, "Largest ball radius in pixels")
      ->check(FiniteRange(0.1, 10000.0))
      ->capture_default_str();
  cmd->add_option("--small-balls", o.small.mode,
                  "Balls of a few pixels mixed with the background: on, off, or auto (with a posed "
                  "camera where the ball looks that small, without one anywhere); without a posed "
                  "camera only on the field")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  cmd->add_option("--off-field-score", o.off_field_min_score,
                  "Without a posed camera: a candidate above the field's far edge (its colour "
                  "seen from the bottom up) is accepted only from this score or as a whole disc "
                  "(0: anywhere)")
      ->check(FiniteRange(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--lit-ratio", o.min_lit_field_ratio,
                  "A candidate whose lit part is darker than this times the field's median "
                  "brightness is rejected (balls reflect more than grass; 0: no check; off for "
                  "the black, blue and green presets)")
      ->check(FiniteRange(0.0, 10.0))
      ->capture_default_str();
}

// The radius limits together (each option checks its own range): in the options' names.
inline void CheckBallSizeOptions(const detect::BallDetectorOptions& o) {
  FV_REQUIRE(o.max_radius_px > o.min_radius_px,
             "--max-radius ({}) must be larger than --min-radius ({})", o.max_radius_px,
             o.min_radius_px);
}

// `--no-background`: the static camera's background is not used (detect/camera_background.h).
inline void AddBackgroundOption(CLI::App* cmd, bool& background) {
  cmd->add_flag(
      "!--no-background", background,
      "Do not compare low-contrast candidates with the camera's background (the median of "
      "frames sampled from its video's first minute; videos of posed, static cameras)");
}

// `auto_for_stills`: the command reads still images too and offers (and defaults to) `auto`,
// which ResolveAutoDetector settles.
inline void AddDetectorOptions(CLI::App* cmd, detect::DnnBallOptions& o,
                               bool auto_for_stills = false) {
  if (auto_for_stills) o.detector = "auto";
  cmd->add_option("--detector", o.detector,
                  std::string("Ball detector: colour (colour table and shape checks), dnn (the "
                              "shipped NanoDet model's COCO 'sports ball' class: any ball, "
                              "slower), or both (the network confirms colour candidates and "
                              "completes them)") +
                      (auto_for_stills ? "; auto: both on still images (a folder, a glob, one "
                                         "image; where the model was built), colour on a video "
                                         "or a numbered frame sequence"
                                       : ""))
      ->check(auto_for_stills ? CLI::IsMember({"auto", "colour", "dnn", "both"})
                              : CLI::IsMember({"colour", "dnn", "both"}))
      ->capture_default_str();
  cmd->add_option("--dnn-width", o.input_width,
                  "With dnn/both: network input width for the whole-frame search (multiple of "
                  "32; 0: the frame's width, at least 416)")
      ->check(NetworkWidth())
      ->capture_default_str();
  cmd->add_option("--dnn-accept", o.accept_score,
                  "With dnn: a network ball is accepted from this score")
      ->check(FiniteRange(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--dnn-confirm", o.confirm_score,
                  "With both: a colour candidate is confirmed (accepted) from this network score "
                  "(in a crop around it or the whole frame)")
      ->check(FiniteRange(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--dnn-complete", o.complete_score,
                  "With both: a network ball where colour found nothing is accepted from this "
                  "score (1: never)")
      ->check(FiniteRange(0.0, 1.0))
      ->capture_default_str();
  cmd->add_flag("!--dnn-crops-only", o.whole_frame,
                "With both: check colour candidates in crops only, no whole-frame search (about "
                "12x faster; nothing completes colour)");
  cmd->add_option("--dnn-keep-score", o.keep_score,
                  "With both: a colour-accepted candidate the network does not confirm is kept "
                  "from this colour score (1: never; colour scores stay below 1)")
      ->check(FiniteRange(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--dnn-keep-field", o.keep_field_share,
                  "With both: a colour-accepted candidate the network does not confirm is also "
                  "kept when at least this share of a ring just around it is field (colour "
                  "vouches for a ball on the carpet; 0: off)")
      ->check(FiniteRange(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--dnn-rescan-step", o.rescan_step_px,
                  "With both: in a frame where nothing is accepted, the colour stage scans "
                  "again at this scanline step and the network judges what it adds (0: off)")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  cmd->add_flag("!--dnn-keep", o.demote_unconfirmed,
                "With both: keep every colour-accepted candidate the network does not confirm "
                "(default: those below --dnn-keep-score and off the field, --dnn-keep-field, are "
                "rejected)");
}

// `--detector auto`: both on still images (io::IsStillImageInput; recall and precision on the
// RoboCup photos for 0.1-0.9 s a frame), colour on a camera's frames. Without the model colour,
// and `notice` says why. Returns the choice for the output's first line ("": not auto).
inline std::string ResolveAutoDetector(detect::DnnBallOptions& o, bool still_images,
                                       std::string* notice) {
  if (o.detector != "auto") return "";
  o.detector = "colour";
  if (!still_images) return "detector: colour (auto: a video or a numbered frame sequence)";
  try {
    if (o.model_path.empty()) o.model_path = dnn::FindModel("nanodet.onnx");
    o.detector = "both";
    return "detector: both (auto: still images; --detector colour for the colour path alone)";
  } catch (const Error& e) {
    *notice = fmt::format("no NanoDet model, so the colour detector alone ({})", e.what());
    return "detector: colour (auto: still images, but no NanoDet model)";
  }
}

// ResolveAutoDetector for the frames `input` names, its warning on stderr; returns what prints
// the choice on stdout (flushed: a run may take minutes), for the run to call once its inputs
// are open (a missing input's error is then the only line).
inline std::function<void()> ChooseAutoDetector(detect::DnnBallOptions& o,
                                                const std::string& input) {
  std::string notice;
  std::string chosen = ResolveAutoDetector(o, io::IsStillImageInput(input), &notice);
  if (!notice.empty()) std::cerr << "fieldvision: warning: " << notice << "\n";
  return [chosen = std::move(chosen)] {
    if (!chosen.empty()) std::cout << chosen << std::endl;
  };
}

}  // namespace fv::app
