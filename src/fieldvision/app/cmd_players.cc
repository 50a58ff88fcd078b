// `fieldvision players`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  AddPlannedCommand(app, "players", "Detect and track players, positions on the field",
                    "writes TRACKS.csv in MOTChallenge layout plus x_m,y_m (players issue)", exit_code);
}

FV_REGISTER_COMMAND(70, "players", Setup);

}  // namespace
}  // namespace fv::app
