// Errors: contract violations and bad input throw fv::Error with a one-line message that names
// the input (file, key, option). Expected failures (no ball, parallel rays) are values instead.
#pragma once

#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace fv {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <typename... Args>
[[noreturn]] void Throw(fmt::format_string<Args...> format, Args&&... args) {
  throw Error(fmt::format(format, std::forward<Args>(args)...));
}

// Throws fv::Error with the formatted message when `cond` is false.
#define FV_REQUIRE(cond, ...)   \
  do {                          \
    if (!(cond)) {              \
      ::fv::Throw(__VA_ARGS__); \
    }                           \
  } while (0)

// Checks for Options::Check(): throw naming the field when the value is out of range.
void CheckPositive(double value, const char* field);
void CheckNonNegative(double value, const char* field);
void CheckInRange(double value, double lo, double hi, const char* field);
void CheckFinite(double value, const char* field);

}  // namespace fv
