// Small string helpers: split, trim, strict number parsing with a named context for errors.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace fv::util {

std::vector<std::string> Split(std::string_view s, char sep);
std::string Trim(std::string_view s);
bool StartsWith(std::string_view s, std::string_view prefix);
bool EndsWith(std::string_view s, std::string_view suffix);
std::string ToLower(std::string_view s);

// Parses the whole string as a number; throws fv::Error naming `context` otherwise.
double ParseDouble(std::string_view s, std::string_view context);
long long ParseInt(std::string_view s, std::string_view context);

}  // namespace fv::util
