// `fieldvision color`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "color", "Colour classes for the ball");
  AddPlannedCommand(*group, "learn", "Learn a colour class from pixels a user points at", "see the ball detection issue", exit_code);
}

FV_REGISTER_COMMAND(30, "color", Setup);

}  // namespace
}  // namespace fv::app
