// `fieldvision detect`: ball candidates in every frame of one camera's video (detect_video.h).
#include <charconv>
#include <iostream>

#include "fieldvision/app/ball_options.h"
#include "fieldvision/app/command.h"
#include "fieldvision/app/detector_options.h"
#include "fieldvision/camera/camera_io.h"
#include "fieldvision/detect/detect_video.h"
#include "fieldvision/io/video_writer.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<detect::DetectVideoOptions>();
  CLI::App* cmd =
      app.add_subcommand("detect",
                         "Find ball candidates in each frame of one camera (colour table, blobs, "
                         "sub-pixel centre); write frame,u,v,radius_px,score,accepted,sigma_px");
  cmd->add_option("--camera", o->camera,
                  "Camera file (YAML); without it no size check or field mask");
  cmd->add_option("--video", o->video, "Video file or image pattern (dir/%05d.png)")->required();
  cmd->add_option("--out", o->out, "CSV of every candidate per frame")->required();
  AddBallColourOption(cmd, o->detector.colour);
  AddBallDiameterOption(cmd, o->detector.diameter_m);
  cmd->add_option("--field", o->field,
                  "Field (built-in name or JSON): ignore everything outside the field of play "
                  "(needs a camera with a pose)");
  cmd->add_option(
      "--draw", o->draw,
      "Draw the candidates: an annotated video (.mp4: H.264 where OpenCV's FFmpeg has it, else "
      "Motion-JPEG as .avi; .avi, .mkv: Motion-JPEG), an image (.jpg, .png: one frame only) or "
      "a folder of JPEGs");
  AddScanStepOption(cmd, o->detector);
  AddBallSizeOptions(cmd, o->detector);
  AddDetectorOptions(cmd, o->dnn, /*auto_for_stills=*/true);
  AddBackgroundOption(cmd, o->background);
  cmd->add_option("--max-frames", o->max_frames, "Stop after this many frames (-1: all)")
      ->check(CLI::Validator(
          [](const std::string& v) -> std::string {
            long long n = 0;
            const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), n);
            const bool whole = ec == std::errc() && end == v.data() + v.size();
            return whole && (n == -1 || (n > 0 && n <= 1000000000))
                       ? ""
                       : "'" + v + "': give -1 (all frames) or a count from 1";
          },
          "-1 or > 0"));
  cmd->add_flag("!--no-progress", o->progress, "Do not show progress");
  cmd->callback([o] {
    CheckBallSizeOptions(o->detector);
    // The field mask is the field seen through a posed camera; without one --field did nothing.
    FV_REQUIRE(
        o->field.empty() || (!o->camera.empty() && camera::ReadCameraYaml(o->camera).has_pose),
        "detect: --field needs --camera with a pose (the field is found through it)");
    util::CheckOutputPath(o->out,
                          util::PathList(o->video, o->camera, o->field, o->detector.colour));
    const auto inputs = util::PathList(o->video, o->camera, o->field, o->out);
    if (io::IsVideoName(o->draw)) {
      io::CheckVideoOutput(o->draw, inputs, "--draw");
    } else {
      util::CheckOutputPath(o->draw, inputs, "--draw");  // an image or a folder of JPEGs
    }
    o->on_start = ChooseAutoDetector(o->dnn, o->video);
    const detect::DetectVideoResult r = detect::DetectVideo(*o);
    std::cout << r.Summary() << "\nwrote " << o->out << "\n";
    if (!r.drawn.empty()) std::cout << "drew " << r.drawn << "\n";
  });
  (void)exit_code;
}

FV_REGISTER_COMMAND(35, "detect", Setup);

}  // namespace
}  // namespace fv::app
