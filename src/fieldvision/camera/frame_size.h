// A camera file against the frames it is used on: the same size, or the frames of a video whose
// encoder coded whole 16x16 blocks and cropped the padding off at the right or bottom (H.264 and
// HEVC frame cropping: a 1920x1080 video is coded as 1920x1088, and frames taken from the coded
// picture, a chessboard session's or a motion-capture system's, are 1088 rows). Cropping at the
// far edges leaves the intrinsics as they are.
#pragma once

#include <string>

#include "fieldvision/camera/camera.h"

namespace fv::camera {

// Whether frames of width x height are the camera's image with an encoder's padding to whole
// 16-pixel blocks cropped off (each side equal, or 1..15 pixels fewer with the camera's side a
// multiple of 16; not both equal).
bool IsCroppedPadding(const Camera& camera, int width, int height);

// The same size: "". IsCroppedPadding: the camera takes the frames' size and the returned note
// says so. Any other size throws fv::Error naming the camera (`camera_what`: "camera file
// 'cam.yaml'") and `video` with both sizes.
std::string FitCameraToFrames(Camera& camera, const std::string& camera_what, int width, int height,
                              const std::string& video);

}  // namespace fv::camera
