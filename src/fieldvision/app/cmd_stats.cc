// `fieldvision stats`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  AddPlannedCommand(app, "stats", "Statistics for coaches from player tracks",
                    "writes stats.json, heat maps and index.html (players issue)", exit_code);
}

FV_REGISTER_COMMAND(75, "stats", Setup);

}  // namespace
}  // namespace fv::app
