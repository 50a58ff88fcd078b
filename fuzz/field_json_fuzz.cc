// libFuzzer harness: field JSON (field/field_json.h). A field that is read must pass
// FieldModel::Check and read back from its own JSON (FieldToJson) the same.
#include <nlohmann/json.hpp>

#include "fieldvision/field/field.h"
#include "fieldvision/field/field_json.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path =
      fv::fuzz::WriteInput({reinterpret_cast<const char*>(data), size}, "field.json");
  fv::fuzz::ExpectErrorOrValue([&] {
    const fv::field::FieldModel field = fv::field::ReadFieldJson(path);
    field.Check();
    const nlohmann::json once = fv::field::FieldToJson(field);
    const nlohmann::json twice = fv::field::FieldToJson(fv::field::FieldFromJson(once, "again"));
    if (once != twice) {
      std::fprintf(stderr, "fuzz: field JSON does not read back the same\n");
      std::abort();
    }
  });
  return 0;
}
