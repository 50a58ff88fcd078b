// `fieldvision calibrate`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "calibrate", "Calibrate cameras: intrinsics, pose from field points, refinement against lines");
  AddPlannedCommand(*group, "intrinsics", "Intrinsics from chessboard/ChArUco images", "see the calibration issue", exit_code);
  AddPlannedCommand(*group, "extrinsics", "Pose from known field points", "see the calibration issue", exit_code);
  AddPlannedCommand(*group, "refine", "Refine the pose against the painted field lines", "see the calibration issue", exit_code);
  AddPlannedCommand(*group, "check", "Draw the field over a frame and report the line error", "see the calibration issue", exit_code);
  AddPlannedCommand(*group, "rig", "Refine several cameras' poses jointly", "see the calibration issue", exit_code);
}

FV_REGISTER_COMMAND(20, "calibrate", Setup);

}  // namespace
}  // namespace fv::app
