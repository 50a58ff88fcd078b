// `fieldvision calibrate import --tsai FILE.xml --out CAM.yaml`: a Tsai calibration (PETS 2009)
// as the camera file of CONTRACT.md.
#include <iostream>

#include "fieldvision/app/command.h"
#include "fieldvision/camera/camera_io.h"
#include "fieldvision/track/pets.h"

namespace fv::app {
namespace {

struct ImportCli {
  std::string tsai, out, name;
};

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(
      app, "calibrate",
      "Calibrate cameras: intrinsics, pose from field points, refinement against lines");
  auto c = std::make_shared<ImportCli>();
  CLI::App* cmd =
      group->add_subcommand("import", "Import a calibration made elsewhere (Tsai XML, as PETS)");
  cmd->add_option("--tsai", c->tsai, "Tsai camera file (e.g. PETS View_001.xml)")->required();
  cmd->add_option("--out", c->out, "Camera file to write (CAM.yaml)")->required();
  cmd->add_option("--name", c->name, "Camera name (default: the Tsai file's name attribute)");
  cmd->callback([c] {
    const track::TsaiParameters p = track::ReadTsaiXml(c->tsai);
    const track::TsaiConversion conv = track::CameraFromTsai(p, c->name.empty() ? "tsai" : c->name);
    WriteCameraYaml(conv.camera, c->out);
    std::cout << conv.Summary() << "\nwrote " << c->out << "\n";
  });
}

FV_REGISTER_COMMAND(21, "calibrate import", Setup);

}  // namespace
}  // namespace fv::app
