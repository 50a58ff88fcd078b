#include "fieldvision/util/json.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/input_file.h"

namespace fv::util {
namespace {

using nlohmann::json;

// "ctx: key 'key'" (or "key 'key'" without a context).
std::string Named(const std::string& key, const std::string& ctx) {
  return ctx.empty() ? fmt::format("key '{}'", key) : fmt::format("{}: key '{}'", ctx, key);
}

// The value under `key`, or nullptr when missing (and a fallback is allowed).
const json* Member(const json& obj, const std::string& key, const std::string& ctx,
                   bool has_fallback) {
  if (JsonHas(obj, key)) return &obj[key];
  if (!has_fallback) ThrowMissingJsonKey(key, ctx);
  return nullptr;
}

}  // namespace

int JsonNestingDepth(std::string_view text, int stop_above) {
  int depth = 0, deepest = 0;
  ScanJsonText(text, [&](char c, bool in_string) {
    if (in_string) return true;
    if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      return deepest <= stop_above;
    }
    if (c == ']' || c == '}') --depth;
    return true;
  });
  return deepest;
}

json ReadJsonFile(const std::string& path, const std::string& what) {
  RequireInputFile(path, what + " file");
  std::ifstream in(path, std::ios::binary);
  FV_REQUIRE(in.good(), "{} file '{}' cannot be read", what, path);
  std::stringstream text;
  text << in.rdbuf();
  FV_REQUIRE(!in.bad(), "{} file '{}' cannot be read", what, path);
  FV_REQUIRE(text.view().find_first_not_of(" \t\r\n") != std::string_view::npos,
             "{} file '{}' is empty", what, path);
  FV_REQUIRE(JsonNestingDepth(text.view()) <= kMaxJsonDepth,
             "{} file '{}' nests arrays or objects deeper than {} levels", what, path,
             kMaxJsonDepth);
  try {
    return json::parse(text.view());
  } catch (const json::parse_error& e) {
    Throw("{} file '{}' is not valid JSON (byte {})", what, path, e.byte);
  } catch (const json::exception& e) {
    // e.g. a number too large for a double.
    Throw("{} file '{}' is not valid JSON: {}", what, path, JsonErrorText(e));
  }
}

std::string JsonErrorText(const json::exception& e) {
  const std::string message = e.what();
  const size_t end = message.find("] ");
  return message.rfind("[json.exception.", 0) == 0 && end != std::string::npos
             ? message.substr(end + 2)
             : message;
}

std::string JsonPath(const std::string& ctx, const std::string& key) {
  return ctx.empty() ? key : ctx + "." + key;
}

bool JsonHas(const json& obj, const std::string& key) {
  return obj.is_object() && obj.contains(key);
}

void ThrowMissingJsonKey(const std::string& key, const std::string& ctx) {
  if (ctx.empty()) Throw("missing key '{}'", key);
  Throw("{}: missing key '{}'", ctx, key);
}

double JsonNumber(const json& obj, const std::string& key, const std::string& ctx,
                  std::optional<double> fallback) {
  const json* v = Member(obj, key, ctx, fallback.has_value());
  if (!v) return *fallback;
  FV_REQUIRE(v->is_number(), "{} must be a number", Named(key, ctx));
  const double x = v->get<double>();
  FV_REQUIRE(std::isfinite(x), "{} is not finite", Named(key, ctx));
  return x;
}

int JsonInt(const json& obj, const std::string& key, const std::string& ctx,
            std::optional<int> fallback) {
  if (fallback && !JsonHas(obj, key)) return *fallback;
  const int64_t v = JsonInt64(obj, key, ctx);
  FV_REQUIRE(v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max(),
             "{} is out of range", Named(key, ctx));
  return static_cast<int>(v);
}

int64_t JsonInt64(const json& obj, const std::string& key, const std::string& ctx,
                  std::optional<int64_t> fallback) {
  const json* v = Member(obj, key, ctx, fallback.has_value());
  if (!v) return *fallback;
  FV_REQUIRE(v->is_number_integer(), "{} must be an integer", Named(key, ctx));
  FV_REQUIRE(!v->is_number_unsigned() ||
                 v->get<uint64_t>() <= static_cast<uint64_t>(std::numeric_limits<int64_t>::max()),
             "{} is out of range", Named(key, ctx));
  return v->get<int64_t>();
}

bool JsonBool(const json& obj, const std::string& key, const std::string& ctx,
              std::optional<bool> fallback) {
  const json* v = Member(obj, key, ctx, fallback.has_value());
  if (!v) return *fallback;
  FV_REQUIRE(v->is_boolean(), "{} must be true or false", Named(key, ctx));
  return v->get<bool>();
}

std::string JsonString(const json& obj, const std::string& key, const std::string& ctx,
                       std::optional<std::string> fallback) {
  const json* v = Member(obj, key, ctx, fallback.has_value());
  if (!v) return *fallback;
  FV_REQUIRE(v->is_string(), "{} must be a string", Named(key, ctx));
  return v->get<std::string>();
}

std::vector<double> JsonNumbers(const json& obj, const std::string& key, const std::string& ctx,
                                bool required) {
  const json* a = Member(obj, key, ctx, !required);
  std::vector<double> out;
  if (!a) return out;
  const std::string name = Named(key, ctx);
  FV_REQUIRE(a->is_array(), "{} must be an array of numbers", name);
  for (size_t i = 0; i < a->size(); ++i) {
    FV_REQUIRE((*a)[i].is_number(), "{} element {} is not a number", name, i);
    out.push_back((*a)[i].get<double>());
    FV_REQUIRE(std::isfinite(out.back()), "{} element {} is not finite", name, i);
  }
  return out;
}

std::vector<double> JsonFixedNumbers(const json& value, int n, const std::string& what) {
  FV_REQUIRE(value.is_array() && value.size() == static_cast<size_t>(n),
             "{} must be an array of {} numbers", what, n);
  std::vector<double> out;
  for (int i = 0; i < n; ++i) {
    FV_REQUIRE(value[i].is_number(), "{} element {} is not a number", what, i);
    out.push_back(value[i].get<double>());
    FV_REQUIRE(std::isfinite(out.back()), "{} element {} is not finite", what, i);
  }
  return out;
}

const json& JsonArray(const json& obj, const std::string& key, const std::string& ctx) {
  static const json kEmpty = json::array();
  if (!JsonHas(obj, key)) return kEmpty;
  FV_REQUIRE(obj[key].is_array(), "{} must be an array", Named(key, ctx));
  return obj[key];
}

const json& JsonObject(const json& obj, const std::string& key, const std::string& ctx) {
  static const json kEmpty = json::object();
  if (!JsonHas(obj, key)) return kEmpty;
  FV_REQUIRE(obj[key].is_object(), "{} must be an object", Named(key, ctx));
  return obj[key];
}

void JsonKnownKeys(const json& obj, const std::string& ctx,
                   std::initializer_list<const char*> known) {
  FV_REQUIRE(obj.is_object(), "{} must be an object", ctx.empty() ? "the document" : ctx);
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    bool ok = false;
    for (const char* k : known) ok = ok || it.key() == k;
    if (ok) continue;
    if (ctx.empty()) Throw("unknown key '{}' (known: {})", it.key(), fmt::join(known, ", "));
    Throw("{}: unknown key '{}' (known: {})", ctx, it.key(), fmt::join(known, ", "));
  }
}

json JsonFromVector(const Eigen::VectorXd& v) {
  json a = json::array();
  for (int i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

json JsonFromVector(const Eigen::VectorXd& v, int decimals) {
  json a = json::array();
  for (int i = 0; i < v.size(); ++i) a.push_back(JsonRound(v[i], decimals));
  return a;
}

double JsonRound(double v, int decimals) {
  const double f = std::pow(10.0, decimals);
  return std::round(v * f) / f;
}

}  // namespace fv::util
