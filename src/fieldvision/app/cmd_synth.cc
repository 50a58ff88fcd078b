// `fieldvision synth`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  AddPlannedCommand(app, "synth", "Render synthetic scenes with exact ground truth",
                    "renders N calibrated cameras looking at a field with a ball, players and distractors (foundation issue)", exit_code);
}

FV_REGISTER_COMMAND(10, "synth", Setup);

}  // namespace
}  // namespace fv::app
