// `fieldvision fuse`: the fusion node; pairs the camera nodes' detections by capture time,
// places the ball in 3D, writes BALL.csv and publishes positions (net/fuse.h).
#include <csignal>
#include <iostream>
#include <memory>

#include "fieldvision/app/command.h"
#include "fieldvision/io/output_path.h"
#include "fieldvision/net/fuse.h"

namespace fv::app {
namespace {

pipeline::JobControl* g_fuse_control = nullptr;

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
      ->check(FiniteRange(0, 60))
      ->capture_default_str();
  cmd->add_option("--ball-diameter", o->ball_diameter_m, "Ball diameter in metres")
      ->check(FiniteRange(0.01, 2))
      ->capture_default_str();
  cmd->add_option("--inlier-px", o->triangulation.inlier_threshold_px,
                  "A camera agrees when it sees the ball within this many pixels")
      ->check(FiniteRange(0.01, 1000))
      ->capture_default_str();
  cmd->add_flag("--ground", o->triangulation.single_camera_ground,
                "Seen by one camera only: place the ball on the ground (n_cams 1)");
  cmd->add_flag("!--no-weak", o->triangulation.use_weak,
                "Never use candidates that failed a shape check to complete a position");
  cmd->add_flag("!--no-flights", o->flights,
                "Do not analyse flights (published on topic `flight` as each one closes)");
  cmd->add_flag("!--no-progress", o->progress, "Do not show progress");
  cmd->callback([o, &exit_code] {
    io::CheckOutputPath(o->out, o->cameras);
    pipeline::JobControl control;
    g_fuse_control = &control;
    auto on_signal = [](int) {
      if (g_fuse_control != nullptr) g_fuse_control->Stop();
    };
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    o->control = &control;
    o->on_listening = [](const std::string& endpoint) {
      std::cout << "fuse: listening on " << endpoint << std::endl;
    };
    const net::FuseSummary s = net::RunFuse(*o);
    g_fuse_control = nullptr;
    std::cout << s.ToString() << "\n";
    std::cout << "wrote " << o->out << " (" << s.rows_written << " rows)\n";
  });
}

FV_REGISTER_COMMAND(46, "fuse", Setup);

}  // namespace
}  // namespace fv::app
