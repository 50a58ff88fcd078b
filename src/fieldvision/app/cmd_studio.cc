// `fieldvision studio`: serves the local web app (web/studio_server.h) over the current folder.
#include <filesystem>
#include <iostream>
#include <memory>

#include "fieldvision/app/command.h"
#include "fieldvision/util/error.h"
#include "fieldvision/web/studio_server.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<web::StudioOptions>();
  CLI::App* cmd = app.add_subcommand(
      "studio",
      "Serve the studio web app (calibrate by clicking, ball colour, 3D view, tactical board) "
      "over the current folder; reads and writes only inside it");
  cmd->add_option("--host", o->host,
                  "Address to bind; any other than loopback requires the printed token")
      ->capture_default_str();
  cmd->add_option("--port", o->port, "Port (0: any free one)")
      ->check(FiniteRange(0, 65535))
      ->capture_default_str();
  cmd->add_option("--token", o->token, "Token for a non-loopback --host (default: random)");
  cmd->add_option("--live", o->live,
                  "Subscribe the 3D view's live mode to a fusion node's positions from the start "
                  "(its --publish address, tcp://HOST:PORT)")
      ->check(Endpoint(/*bind=*/false));
  cmd->add_option("--assets", o->assets,
                  "Folder of the built front end (default: studio/dist of the source tree, else "
                  "share/fieldvision/studio of the install)");
  cmd->callback([o, &exit_code] {
    // A front end given by hand must be there (the default one may be unbuilt: the page says so).
    FV_REQUIRE(o->assets.empty() || std::filesystem::is_regular_file(
                                        std::filesystem::path(o->assets) / "index.html"),
               "studio: --assets '{}' is not a folder with index.html (the built front end, "
               "studio/dist)",
               o->assets);
    exit_code = web::RunStudio(*o, std::cout);
  });
}

FV_REGISTER_COMMAND(95, "studio", Setup);

}  // namespace
}  // namespace fv::app
