// `fieldvision plan`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  AddPlannedCommand(app, "plan", "Plan camera placement: coverage, angles, expected error",
                    "writes coverage images and coverage.json (camera planner issue)", exit_code);
}

FV_REGISTER_COMMAND(60, "plan", Setup);

}  // namespace
}  // namespace fv::app
