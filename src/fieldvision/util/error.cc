#include "fieldvision/util/error.h"

#include <cmath>

namespace fv {

void CheckFinite(double value, const char* field) {
  FV_REQUIRE(std::isfinite(value), "{} must be finite (got {})", field, value);
}

void CheckPositive(double value, const char* field) {
  CheckFinite(value, field);
  FV_REQUIRE(value > 0, "{} must be > 0 (got {})", field, value);
}

void CheckNonNegative(double value, const char* field) {
  CheckFinite(value, field);
  FV_REQUIRE(value >= 0, "{} must be >= 0 (got {})", field, value);
}

void CheckInRange(double value, double lo, double hi, const char* field) {
  CheckFinite(value, field);
  FV_REQUIRE(value >= lo && value <= hi, "{} must be in [{}, {}] (got {})", field, lo, hi, value);
}

}  // namespace fv
