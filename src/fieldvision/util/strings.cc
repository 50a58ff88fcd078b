#include "fieldvision/util/strings.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>

#include "fieldvision/util/error.h"

namespace fv::util {

std::vector<std::string> Split(std::string_view s, char sep) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t pos = s.find(sep, start);
    if (pos == std::string_view::npos) {
      out.emplace_back(s.substr(start));
      return out;
    }
    out.emplace_back(s.substr(start, pos - start));
    start = pos + 1;
  }
}

std::string Trim(std::string_view s) {
  size_t b = 0;
  size_t e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return std::string(s.substr(b, e - b));
}

bool StartsWith(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

bool EndsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

std::string ToLower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::string ReplaceAll(std::string text, std::string_view from, std::string_view to) {
  if (from.empty()) return text;
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

std::string FileNamePart(std::string_view s) {
  std::string out(s);
  for (char& c : out) {
    // Bytes of UTF-8 sequences (>= 0x80) are never '/' or '.': names in any script stay.
    const auto b = static_cast<unsigned char>(c);
    const bool keep = b >= 0x80 || std::isalnum(b) || c == '-' || c == '_' || c == '.';
    if (!keep) c = '_';
  }
  // Not a hidden file: leading dots become '_' too.
  for (size_t i = 0; i < out.size() && out[i] == '.'; ++i) out[i] = '_';
  return out;
}

namespace {
constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
}  // namespace

void SkipUtf8Bom(std::istream& in) {
  if (in.peek() != 0xEF) return;
  const std::istream::pos_type start = in.tellg();
  char bytes[3] = {};
  in.read(bytes, 3);
  if (in.gcount() == 3 && std::string_view(bytes, 3) == kUtf8Bom) return;
  in.clear();
  in.seekg(start);  // not a mark: read from the start as it is
}

std::string_view WithoutUtf8Bom(std::string_view text) {
  return text.substr(0, kUtf8Bom.size()) == kUtf8Bom ? text.substr(kUtf8Bom.size()) : text;
}

std::string Shown(std::string_view t) {
  std::string out(t.substr(0, 40));
  for (char& c : out) {
    if (std::iscntrl(static_cast<unsigned char>(c))) c = '?';
  }
  return t.size() > 40 ? out + "..." : out;
}

std::string JoinNonEmpty(const std::vector<std::string>& parts, std::string_view sep) {
  std::string out;
  for (const std::string& p : parts) {
    if (p.empty()) continue;
    if (!out.empty()) out += sep;
    out += p;
  }
  return out;
}

double ParseDouble(std::string_view s, std::string_view context) {
  const std::string t = Trim(s);
  FV_REQUIRE(!t.empty(), "{}: empty value where a number is expected", context);
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  FV_REQUIRE(end == t.c_str() + t.size(), "{}: '{}' is not a number", context, Shown(t));
  return v;
}

long long ParseInt(std::string_view s, std::string_view context) {
  const std::string t = Trim(s);
  long long v = 0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  FV_REQUIRE(ec == std::errc() && ptr == t.data() + t.size() && !t.empty(),
             "{}: '{}' is not an integer", context, Shown(t));
  return v;
}

uint64_t Fnv1a64(std::string_view s) {
  uint64_t h = 14695981039346656037ull;
  for (const char c : s) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return h;
}

}  // namespace fv::util
