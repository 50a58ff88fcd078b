// `fieldvision fuse`: the fusion node; pairs the camera nodes' detections by capture time,
// places the ball in 3D, writes BALL.csv and publishes positions (net/fuse.h).
#include <iostream>
#include <memory>

#include "fieldvision/app/ball_options.h"
#include "fieldvision/app/command.h"
#include "fieldvision/app/stop_on_signal.h"
#include "fieldvision/net/fuse.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<net::FuseOptions>();
  CLI::App* cmd = app.add_subcommand(
      "fuse", "Fusion node: pair the camera nodes' detections, place the ball in 3D; BALL.csv");
  cmd->add_option("--listen", o->listen,
                  "Where nodes connect, tcp://HOST:PORT (use 127.0.0.1 unless other machines "
                  "must reach it; PORT * takes a free port)")
      ->check(Endpoint(true))
      ->required();
  cmd->add_option("--camera", o->cameras, "Camera file (repeat); nodes are matched by name")
      ->required();
  cmd->add_option("--out", o->out, "BALL.csv: frame,time_s,x_m,y_m,z_m,n_cams,err_px")->required();
  cmd->add_option(
         "--publish", o->publish,
         "Publish each position on a ZeroMQ PUB socket, tcp://HOST:PORT (topic 'ball'), and "
         "each flight as it closes (topic 'flight')")
      ->check(Endpoint(true));
  cmd->add_option("--idle-exit", o->idle_exit_s,
                  "Exit after this many seconds without messages, counted once the first has come; "
                  "running nodes ping every 0.5 s (0: run until Ctrl-C)")
      ->check(FiniteRange(0, 86400))
      ->capture_default_str();
  cmd->add_option("--tolerance", o->sync.tolerance_s,
                  "Frames this close in capture time (s) are paired")
      ->check(FiniteRange(1e-6, 1))
      ->capture_default_str();
  cmd->add_option("--max-wait", o->sync.max_wait_s,
                  "Longest wait (s) for a slow camera before a frame is fused without it")
      ->check(FiniteRange(0.001, 60))
      ->capture_default_str();
  cmd->add_option("--media-max-wait", o->media_max_wait_s,
                  "The same for nodes reading files as fast as they can (not --realtime): a "
                  "slower node is not late, only slower")
      ->check(FiniteRange(0, 9))
      ->capture_default_str();
  cmd->add_option("--max-time-jump", o->sync.max_time_jump_s,
                  "A frame stamped further than this (s) from its camera's stream is dropped as "
                  "a bad time, until the camera stays in the new time base for three frames (0: "
                  "off)")
      ->check(FiniteRange(0, 86400))
      ->capture_default_str();
  AddBallDiameterOption(cmd, o->ball_diameter_m);
  AddFusionOptions(cmd, o->triangulation);
  cmd->add_flag("!--no-flights", o->flights,
                "Do not analyse flights (published on topic `flight` as each one closes)");
  cmd->add_flag("!--no-hints", o->hints,
                "Do not send the nodes hints (each fused position off the ground, where their "
                "cameras then look for the ball)");
  cmd->add_flag("!--no-progress", o->progress, "Do not show progress");
  cmd->callback([o, &exit_code] {
    util::CheckOutputPath(o->out, o->cameras);
    pipeline::JobControl control;
    const StopOnSignal stop_on_signal(control);
    o->control = &control;
    o->on_listening = [](const std::string& endpoint) {
      std::cout << "fuse: listening on " << endpoint << std::endl;
    };
    const net::FuseSummary s = net::RunFuse(*o);
    std::cout << s.ToString() << "\n";
    FV_REQUIRE(s.written || s.messages > 0,
               "fuse: no message arrived, {} not written (do the nodes' --connect addresses "
               "reach --listen {}?)",
               o->out, o->listen);
    FV_REQUIRE(s.written,
               "fuse: {} messages arrived but no frame could be fused (see the counts above: "
               "{} frames, none with two cameras or a position), {} not written",
               s.messages, s.groups, o->out);
    std::cout << "wrote " << o->out << " (" << s.rows_written << " rows)\n";
  });
}

FV_REGISTER_COMMAND(46, "fuse", Setup);

}  // namespace
}  // namespace fv::app
