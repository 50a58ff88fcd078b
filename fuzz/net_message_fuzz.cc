// libFuzzer harness: network messages, net::Decode (net/messages.h: every message type) and the
// pipeline's CameraMessage JSON lines (pipeline/camera_message.h). A message that decodes must
// encode and decode again to the same encoding.
#include "fieldvision/net/messages.h"
#include "fieldvision/pipeline/camera_message.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fv::fuzz::ExpectErrorOrValue([&] {
    const fv::net::Message message = fv::net::Decode(data, size);
    const std::string once = fv::net::Encode(message);
    const std::string twice = fv::net::Encode(fv::net::Decode(once.data(), once.size()));
    if (once != twice) {
      std::fprintf(stderr, "fuzz: message does not round-trip:\n%s\n%s\n", once.c_str(),
                   twice.c_str());
      std::abort();
    }
  });
  fv::fuzz::ExpectErrorOrValue([&] {
    const auto message = fv::pipeline::CameraMessage::FromJsonLine(
        {reinterpret_cast<const char*>(data), size}, "fuzz");
    const std::string once = message.ToJsonLine();
    if (fv::pipeline::CameraMessage::FromJsonLine(once, "again").ToJsonLine() != once) {
      std::fprintf(stderr, "fuzz: camera message does not round-trip: %s\n", once.c_str());
      std::abort();
    }
  });
  return 0;
}
