// `fieldvision detect`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  AddPlannedCommand(app, "detect", "Find ball candidates in each frame of one camera",
                    "colour lookup table, scanlines, run lengths, blobs, sub-pixel centre (ball detection issue)", exit_code);
}

FV_REGISTER_COMMAND(35, "detect", Setup);

}  // namespace
}  // namespace fv::app
