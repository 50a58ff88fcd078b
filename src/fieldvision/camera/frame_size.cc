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
  return (camera.height == height && PaddedSide(camera.width, width)) ||
         (camera.width == width && PaddedSide(camera.height, height));
}

std::string FitCameraToFrames(Camera& camera, const std::string& camera_what, int width, int height,
                              const std::string& video) {
  if (camera.width == width && camera.height == height) return "";
  FV_REQUIRE(IsCroppedPadding(camera, width, height),
             "{} is for {}x{} images but video '{}' is {}x{}: use the camera file made for this "
             "video",
             camera_what, camera.width, camera.height, video, width, height);
  std::string note = fmt::format(
      "{} is for {}x{} images, video '{}' is {}x{}: taken as the encoder's padding to {}-pixel "
      "blocks cropped off at the {} (the intrinsics kept)",
      camera_what, camera.width, camera.height, video, width, height, kBlockPx,
      camera.width != width ? "right" : "bottom");
  camera.width = width;
  camera.height = height;
  return note;
}

}  // namespace fv::camera
