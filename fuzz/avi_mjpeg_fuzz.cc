// libFuzzer harness: Motion-JPEG AVI files (io/avi_mjpeg.h). Whatever the bytes, Open gives a
// reader or nullptr and Next ends; a frame is never larger than the file.
#include <vector>

#include "fieldvision/io/avi_mjpeg.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path =
      fv::fuzz::WriteInput({reinterpret_cast<const char*>(data), size}, "video.avi");
  fv::fuzz::ExpectErrorOrValue([&] {
    auto reader = fv::io::AviMjpegReader::Open(path);
    if (!reader) return;
    std::vector<uint8_t> jpeg;
    // Every frame takes at least its 8-byte chunk header: more than size / 8 is a loop.
    for (size_t frames = 0; reader->Next(&jpeg); ++frames) {
      if (jpeg.empty() || jpeg.size() > size || frames > size / 8) {
        std::fprintf(stderr, "fuzz: frame %zu of %zu bytes from a %zu-byte file\n", frames,
                     jpeg.size(), size);
        std::abort();
      }
    }
  });
  return 0;
}
