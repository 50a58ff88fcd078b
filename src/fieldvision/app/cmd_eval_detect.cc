// `fieldvision eval detect`: the ball detector's recall, precision and centre error on labelled
// frames (detect/detect_eval.h).
#include <iostream>
#include <memory>

#include "fieldvision/app/ball_options.h"
#include "fieldvision/app/command.h"
#include "fieldvision/app/detector_options.h"
#include "fieldvision/detect/detect_eval.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "eval");
  auto o = std::make_shared<detect::DetectEvalOptions>();
  CLI::App* cmd = group->add_subcommand(
      "detect",
      "Recall, precision and centre error of the ball detector on labelled frames (best accepted "
      "candidate per image; a hit when its centre is inside a box grown by --grow)");
  cmd->add_option("--video", o->video,
                  "Images (a folder, searched recursively; a glob; dir/%05d.jpg) or a video file")
      ->required();
  cmd->add_option("--labels", o->labels.labels,
                  "Folder of YOLO txt files (class cx cy w h, normalised; default: beside the "
                  "images), a CSV with image|frame,x,y,w,h in pixels, or synth's truth_2d.csv");
  cmd->add_option("--class", o->labels.class_id, "YOLO class of the ball")->capture_default_str();
  cmd->add_option("--label-cam", o->labels.camera,
                  "truth_2d.csv: the camera whose rows label the video (default: the video's "
                  "name, cam1.avi -> cam1, else its folder's, cam1/%05d.png -> cam1)");
  cmd->add_option("--min-visible", o->labels.min_visible,
                  "truth_2d.csv: frames whose ball is less visible than this share are not judged")
      ->check(FiniteRange(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--camera", o->camera, "Camera file (size checks)");
  cmd->add_option("--field", o->field,
                  "Field (built-in name or JSON): ignore everything outside the field of play, as "
                  "`detect --field` (needs --camera with a pose)");
  AddBallColourOption(cmd, o->detector.colour);
  AddScanStepOption(cmd, o->detector);
  AddBallSizeOptions(cmd, o->detector);
  AddDetectorOptions(cmd, o->dnn, /*auto_for_stills=*/true);
  AddBackgroundOption(cmd, o->background);
  cmd->add_option("--grow", o->grow, "Box growth for a hit, each side (share of the box)")
      ->check(FiniteRange(0.0, 5.0))
      ->capture_default_str();
  cmd->add_option("--list", o->list_misses, "Misses and false detections to list")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  cmd->add_option("--out", o->out, "CSV with one row per image");
  cmd->add_option("--candidates", o->candidates_out,
                  "CSV with every candidate and its measurements (for diagnosis)");
  cmd->add_option("--draw-misses", o->draw_misses,
                  "New (or empty) folder: each miss and false detection drawn as a JPEG (the "
                  "labelled box, every candidate, the reason)");
  cmd->add_flag("!--no-progress", o->progress, "Do not show progress");
  cmd->callback([o] {
    CheckBallSizeOptions(o->detector);
    o->on_start = ChooseAutoDetector(o->dnn, o->video);
    const detect::DetectEvalResult r = detect::EvaluateDetector(*o);
    std::cout << r.Summary(o->list_misses) << "\n";
  });
  (void)exit_code;
}

FV_REGISTER_COMMAND(82, "eval detect", Setup);

}  // namespace
}  // namespace fv::app
