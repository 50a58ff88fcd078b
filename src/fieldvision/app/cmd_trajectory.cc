// `fieldvision trajectory`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  AddPlannedCommand(app, "trajectory", "Split a ball track into flights and fit them",
                    "writes FLIGHTS.json with origin, landing, apex, v0 (ball flights issue)", exit_code);
}

FV_REGISTER_COMMAND(50, "trajectory", Setup);

}  // namespace
}  // namespace fv::app
