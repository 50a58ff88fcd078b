// `fieldvision node`: a camera node; finds the ball in one camera's frames and sends timestamped
// detections to the fusion node (net/node.h).
#include <iostream>
#include <memory>

#include "fieldvision/app/ball_options.h"
#include "fieldvision/app/command.h"
#include "fieldvision/app/detector_options.h"
#include "fieldvision/app/stop_on_signal.h"
#include "fieldvision/net/node.h"
#include "fieldvision/util/error.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<net::NodeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "node", "Camera node: find the ball in one camera and send detections to `fuse`");
  cmd->add_option("--camera", o->camera, "Camera file (its name, else its stem, names it)")
      ->required();
  cmd->add_option("--video", o->video,
                  "Video file, image pattern, v4l2:/dev/videoN, rtsp://..., gst:PIPELINE, "
                  "aravis:[ID] or synth:PRESET?camera=NAME")
      ->required();
  cmd->add_option("--connect", o->connect, "The fusion node, tcp://HOST:PORT")
      ->check(Endpoint(false))
      ->required();
  CLI::Option* realtime =
      cmd->add_flag("--realtime", o->realtime,
                    "Play a file at its own frame rate, as a live camera would deliver it");
  cmd->add_option("--start-at", o->start_at_s,
                  "With --realtime: Unix time (s) of frame 0, as for cameras triggered together")
      ->check(FiniteRange(0, 1e10))
      ->needs(realtime);
  cmd->add_option("--fps", o->fps,
                  "Frames per second of the video (an image sequence has none of its own: give "
                  "it); default: the video's own")
      ->check(FiniteRange(1e-3, 100000.0));
  cmd->add_option("--live-buffer", o->live_buffer_frames,
                  "Frames a live source holds for a slow node (the oldest are dropped; 2 absorbs "
                  "one slow frame; 1: only the newest, for a node too slow on average)")
      ->check(FiniteRange(1, 1000))
      ->capture_default_str();
  AddBallDiameterOption(cmd, o->ball_diameter_m);
  AddBallColourOption(cmd, o->colour);
  cmd->add_option("--field", o->field, "Field (name or JSON): look for the ball only over it");
  cmd->add_option("--max-frames", o->max_frames, "Stop after this many frames (0: all)")
      ->check(FiniteRange(0, 1e12));
  AddTrackOptions(cmd, o->track);
  cmd->add_option("--connect-wait", o->connect_wait_s,
                  "Seconds to wait for the fusion node's first clock reply before starting")
      ->check(FiniteRange(0, 3600))
      ->capture_default_str();
  cmd->add_option("--clock-offset", o->clock_offset_s,
                  "Testing: add this many seconds to this node's clock (a machine whose clock "
                  "is off)")
      ->check(FiniteRange(-86400, 86400));
  cmd->add_flag("!--no-detect", o->detect,
                "Send frames without looking for the ball (a latency baseline)");
  cmd->add_flag("!--no-hints", o->hints,
                "Ignore the fusion node's hints (where the cameras together saw the ball); by "
                "default the camera looks there when its own track lost the ball or follows "
                "something else, as the offline `ball` does");
  AddBackgroundOption(cmd, o->background);
  cmd->add_flag("!--no-progress", o->progress, "Do not show progress");
  cmd->callback([o, &exit_code] {
    CheckTrackOptions(o->track);
    pipeline::JobControl control;
    const StopOnSignal stop_on_signal(control);
    o->control = &control;
    const net::NodeSummary s = net::RunNode(*o);
    std::cout << s.ToString() << "\n";
    // A node whose fusion node never answered has done nothing: say so in the exit code.
    FV_REQUIRE(s.frames == 0 || s.sent > 0 || s.has_offset,
               "node: --connect '{}': the fusion node never answered; none of the {} frames was "
               "sent (is `fieldvision fuse --listen` running there?)",
               o->connect, s.frames);
  });
}

FV_REGISTER_COMMAND(45, "node", Setup);

}  // namespace
}  // namespace fv::app
