#include "fieldvision/camera/frame_size.h"

#include <fmt/format.h>

#include "fieldvision/util/error.h"

namespace fv::camera {
namespace {

constexpr int kBlockPx = 16;  // the largest macroblock of H.264 (HEVC pads to 8 or 16 too)

// The camera's side is the frames' side padded to whole blocks.
bool PaddedSide(int camera_px, int frames_px) {
  return camera_px > frames_px && camera_px - frames_px < kBlockPx && camera_px % kBlockPx == 0;
}

}  // namespace

bool IsCroppedPadding(const Camera& camera, int width, int height) {
  const bool same_width = camera.width == width, same_height = camera.height == height;
  return !(same_width && same_height) && (same_width || PaddedSide(camera.width, width)) &&
         (same_height || PaddedSide(camera.height, height));
}

std::string FitCameraToFrames(Camera& camera, const std::string& camera_what, int width, int height,
                              const std::string& frames_what) {
  if (camera.width == width && camera.height == height) return "";
  FV_REQUIRE(IsCroppedPadding(camera, width, height),
             "{} is for {}x{} images but {} is {}x{}: use the camera file made for it", camera_what,
             camera.width, camera.height, frames_what, width, height);
  std::string note = fmt::format(
      "{} is for {}x{} images, {} is {}x{}: taken as the encoder's padding to {}-pixel blocks "
      "cropped off at the {} (the intrinsics kept)",
      camera_what, camera.width, camera.height, frames_what, width, height, kBlockPx,
      camera.width == width ? "bottom" : (camera.height == height ? "right" : "right and bottom"));
  camera.width = width;
  camera.height = height;
  return note;
}

}  // namespace fv::camera
