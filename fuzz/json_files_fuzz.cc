// libFuzzer harness: the JSON file readers other than the field's (field_json_fuzz.cc). The first
// byte picks one: rig (plan/rig_json.h), zones (stats/stats.h), mount places (plan/optimize.h),
// synth scene (synth/synth.h); the rest is the file.
#include "fieldvision/plan/optimize.h"
#include "fieldvision/plan/rig_json.h"
#include "fieldvision/stats/stats.h"
#include "fieldvision/synth/synth.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  fv::fuzz::ExpectErrorOrValue([&] {
    switch (data[0] % 4) {
      case 0:
        (void)fv::plan::ReadRigJson(fv::fuzz::WriteInput(text, "rig.json"));
        break;
      case 1:
        (void)fv::stats::ReadZones(fv::fuzz::WriteInput(text, "zones.json"));
        break;
      case 2:
        (void)fv::plan::ReadMountsJson(fv::fuzz::WriteInput(text, "mounts.json"));
        break;
      default:
        (void)fv::synth::ReadSceneSpec(fv::fuzz::WriteInput(text, "scene.json"));
        break;
    }
  });
  return 0;
}
