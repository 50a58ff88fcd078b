// `fieldvision eval tracks`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "eval", "Compare results with ground truth");
  AddPlannedCommand(*group, "tracks", "MOTA, MOTP, IDF1 of player tracks against ground truth",
                    "see the players issue", exit_code);
}

FV_REGISTER_COMMAND(81, "eval tracks", Setup);

}  // namespace
}  // namespace fv::app
