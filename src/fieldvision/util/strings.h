// Small string helpers: split, trim, strict number parsing with a named context for errors, and a
// stable 64-bit hash (FNV-1a: the same on every compiler and run, unlike std::hash).
#pragma once

#include <cstdint>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

namespace fv::util {

std::vector<std::string> Split(std::string_view s, char sep);
std::string Trim(std::string_view s);
bool StartsWith(std::string_view s, std::string_view prefix);
bool EndsWith(std::string_view s, std::string_view suffix);
std::string ToLower(std::string_view s);
// `text` with every occurrence of `from` (not empty) replaced by `to`, left to right; what `to`
// brings in is not searched again.
std::string ReplaceAll(std::string text, std::string_view from, std::string_view to);
// The non-empty ones of `parts` joined by `sep` ("" when all are empty).
std::string JoinNonEmpty(const std::vector<std::string>& parts, std::string_view sep);
// `s` as part of a file name: ASCII letters, digits, '-', '_', '.' and non-ASCII (UTF-8) bytes
// kept, every other byte and leading dots '_' (so never a path, nor a hidden file).
std::string FileNamePart(std::string_view s);
// Skips a UTF-8 byte-order mark at the stream's start (spreadsheets write one before a CSV's
// header: "CSV UTF-8" in Excel); other bytes are left unread.
void SkipUtf8Bom(std::istream& in);
// `text` without a UTF-8 byte-order mark at its start (the same text when it has none).
std::string_view WithoutUtf8Bom(std::string_view text);

// A value as an error message shows it: one line (control characters as '?'), at most 40
// characters and "...", so that a file's bytes never make a message several lines.
std::string Shown(std::string_view t);

// Parses the whole string as a number; throws fv::Error naming `context` otherwise.
double ParseDouble(std::string_view s, std::string_view context);
long long ParseInt(std::string_view s, std::string_view context);

// 64-bit FNV-1a of the bytes of `s` (Fowler, Noll, Vo).
uint64_t Fnv1a64(std::string_view s);

}  // namespace fv::util
