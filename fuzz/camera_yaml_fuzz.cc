// libFuzzer harness: camera files (camera/camera_io.h, OpenCV FileStorage YAML). A camera that is
// read must pass Camera::Check, back-project its principal point, and read back the same after
// WriteCameraYaml.
#include <cmath>

#include "fieldvision/camera/camera_io.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path =
      fv::fuzz::WriteInput({reinterpret_cast<const char*>(data), size}, "camera.yaml");
  fv::fuzz::ExpectErrorOrValue([&] {
    const fv::camera::Camera camera = fv::camera::ReadCameraYaml(path);
    try {
      camera.Check("fuzz");
    } catch (const fv::Error& e) {
      std::fprintf(stderr, "fuzz: a camera that was read fails Check: %s\n", e.what());
      std::abort();
    }
    (void)camera.RayFromPixel({camera.cx, camera.cy});
    const std::string again = (fv::fuzz::ScratchDir() / "again.yaml").string();
    fv::camera::WriteCameraYaml(camera, again);
    const fv::camera::Camera back = fv::camera::ReadCameraYaml(again);
    if (back.width != camera.width || back.height != camera.height || back.fx != camera.fx ||
        back.distortion.size() != camera.distortion.size()) {
      std::fprintf(stderr, "fuzz: camera file does not read back the same\n");
      std::abort();
    }
  });
  return 0;
}
