// On-disk cache of compiled colour tables (as ssl-vision keeps its lookup tables in files):
// building a 16 MB table converts all 2^24 colours (0.1 s of CPU), loading one is a few
// milliseconds. A file holds the table's key (its spec and format) and the table run-length
// encoded; it is written to a temporary file and renamed, and one that does not read back whole
// with the same key is no table. The folder is $XDG_CACHE_HOME/fieldvision (else
// $HOME/.cache/fieldvision); FV_NO_CACHE=1 or no such variable: no cache. It keeps the tables
// used last (kColourCacheFiles, 0.3-0.6 MB each): a load marks a file used, a store removes the
// ones used longest ago beyond that.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "fieldvision/util/huge_buffer.h"

namespace fv::detect {

// The cache folder, or "" when caching is off.
std::string ColourCacheDir();

constexpr size_t kColourCacheFiles = 16;

// The table stored under `key` with exactly `size` entries, or nullopt (no cache, no file, a
// different key, a damaged file).
std::optional<util::HugeBuffer> LoadCachedTable(const std::string& key, size_t size);

// Stores the table under `key`, then prunes the folder to kColourCacheFiles tables; any failure
// (no folder, a full disk) leaves no file and is not an error: the cache is an optimisation.
void StoreCachedTable(const std::string& key, const uint8_t* table, size_t size);

// Removes the colour-table files of `dir` beyond the `keep` used last (by modification time,
// which a load renews); other files stay.
void PruneColourCache(const std::string& dir, size_t keep);

}  // namespace fv::detect
