// `fieldvision eval`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "eval", "Compare results with ground truth");
  AddPlannedCommand(*group, "ball", "Error table of a ball track against truth", "see the ball 3D and players issues", exit_code);

}

FV_REGISTER_COMMAND(80, "eval ball", Setup);

}  // namespace
}  // namespace fv::app
