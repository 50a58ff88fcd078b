// Field models as JSON: the format of custom fields, and what `field show --json` prints.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "fieldvision/field/field.h"

namespace fv::field {

nlohmann::json FieldToJson(const FieldModel& field);
// Throws fv::Error naming `context` and the bad key.
FieldModel FieldFromJson(const nlohmann::json& j, const std::string& context);
FieldModel ReadFieldJson(const std::string& path);
void WriteFieldJson(const FieldModel& field, const std::string& path);

}  // namespace fv::field
