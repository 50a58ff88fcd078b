// `fieldvision ball`: planned; replaced by its implementation.
#include "fieldvision/app/command.h"

namespace fv::app {
namespace {

void Setup(CLI::App& app, int& exit_code) {
  AddPlannedCommand(app, "ball", "Place the ball in 3D from 2..N synchronized cameras",
                    "writes BALL.csv frame,time_s,x_m,y_m,z_m,n_cams,err_px (ball 3D issue)", exit_code);
}

FV_REGISTER_COMMAND(40, "ball", Setup);

}  // namespace
}  // namespace fv::app
