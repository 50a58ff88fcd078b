// Strict readers and writers for the project's JSON files: a reader fails with one line naming the
// context (the file and the path inside it) and the key; vectors are arrays of numbers.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace fv::util {

// The JSON in the file at `path`; `what` names the file in errors ("rig file 'x' does not exist",
// "... cannot be read", "... is not valid JSON (byte n)", "... nests deeper than ...").
nlohmann::json ReadJsonFile(const std::string& path, const std::string& what);
// nlohmann's message without its "[json.exception.NAME.ID] " prefix.
std::string JsonErrorText(const nlohmann::json::exception& e);

// nlohmann's parser is iterative, but copying and dumping a value recurse: a value nested a
// million levels deep overflows the stack there. Readers of untrusted JSON (HTTP bodies, files)
// refuse text nested deeper than this; the project's own files nest a few levels.
inline constexpr int kMaxJsonDepth = 256;
// The deepest nesting of arrays and objects in JSON text (brackets inside strings do not count);
// it stops counting once past `stop_above`.
int JsonNestingDepth(std::string_view text, int stop_above = kMaxJsonDepth);

// Walks JSON text without parsing it: f(c, in_string) for each character, in_string true inside
// a string literal after its opening quote up to and with its closing one (an escaped \" does
// not end it); f returns false to stop.
template <typename F>
void ScanJsonText(std::string_view text, F&& f) {
  bool in_string = false, escaped = false;
  for (const char c : text) {
    const bool inside = in_string;
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    }
    if (!f(c, inside)) return;
  }
}

// "ctx.key", or "key" when ctx is empty: the context of a nested object.
std::string JsonPath(const std::string& ctx, const std::string& key);
// True when `obj` is an object holding `key`.
bool JsonHas(const nlohmann::json& obj, const std::string& key);

// Member readers. A missing key gives `fallback` or, without one, "ctx: missing key 'key'"; a
// value of the wrong type (or not finite) "ctx: key 'key' must be ...".
double JsonNumber(const nlohmann::json& obj, const std::string& key, const std::string& ctx,
                  std::optional<double> fallback = std::nullopt);
int JsonInt(const nlohmann::json& obj, const std::string& key, const std::string& ctx,
            std::optional<int> fallback = std::nullopt);
int64_t JsonInt64(const nlohmann::json& obj, const std::string& key, const std::string& ctx,
                  std::optional<int64_t> fallback = std::nullopt);
bool JsonBool(const nlohmann::json& obj, const std::string& key, const std::string& ctx,
              std::optional<bool> fallback = std::nullopt);
std::string JsonString(const nlohmann::json& obj, const std::string& key, const std::string& ctx,
                       std::optional<std::string> fallback = std::nullopt);
// An array of finite numbers (empty when the key is missing and `required` is false).
std::vector<double> JsonNumbers(const nlohmann::json& obj, const std::string& key,
                                const std::string& ctx, bool required = true);
// The array or object under `key`; an empty one when the key is missing.
const nlohmann::json& JsonArray(const nlohmann::json& obj, const std::string& key,
                                const std::string& ctx);
const nlohmann::json& JsonObject(const nlohmann::json& obj, const std::string& key,
                                 const std::string& ctx);
// Fails on a key not in `known` ("ctx: unknown key 'k' (known: ...)"), so typos do not pass.
void JsonKnownKeys(const nlohmann::json& obj, const std::string& ctx,
                   std::initializer_list<const char*> known);

// A value that must be an array of exactly n finite numbers; `what` names it in errors.
std::vector<double> JsonFixedNumbers(const nlohmann::json& value, int n, const std::string& what);
template <int N>
Eigen::Matrix<double, N, 1> JsonVectorOf(const nlohmann::json& value, const std::string& what) {
  const std::vector<double> v = JsonFixedNumbers(value, N, what);
  return Eigen::Map<const Eigen::Matrix<double, N, 1>>(v.data());
}
// A member that must be an array of N finite numbers.
template <int N>
Eigen::Matrix<double, N, 1> JsonVector(
    const nlohmann::json& obj, const std::string& key, const std::string& ctx,
    std::optional<Eigen::Matrix<double, N, 1>> fallback = std::nullopt);

// [x, y, ...]: a vector written as an array of numbers; with `decimals`, each rounded to that
// many decimals (JsonRound).
nlohmann::json JsonFromVector(const Eigen::VectorXd& v);
nlohmann::json JsonFromVector(const Eigen::VectorXd& v, int decimals);
// round(v 10^decimals) / 10^decimals: a number written with no more digits than it carries.
double JsonRound(double v, int decimals);

// ---- implementation of the template

[[noreturn]] void ThrowMissingJsonKey(const std::string& key, const std::string& ctx);

template <int N>
Eigen::Matrix<double, N, 1> JsonVector(const nlohmann::json& obj, const std::string& key,
                                       const std::string& ctx,
                                       std::optional<Eigen::Matrix<double, N, 1>> fallback) {
  if (!JsonHas(obj, key)) {
    if (fallback) return *fallback;
    ThrowMissingJsonKey(key, ctx);
  }
  return JsonVectorOf<N>(obj[key],
                         (ctx.empty() ? std::string() : ctx + ": ") + "key '" + key + "'");
}

}  // namespace fv::util
