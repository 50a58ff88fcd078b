#include "fieldvision/detect/colour_cache.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "fieldvision/util/strings.h"

namespace fv::detect {
namespace {

namespace fs = std::filesystem;

constexpr char kMagic[] = "FVLUT1\n";
constexpr size_t kMagicSize = sizeof(kMagic) - 1;

std::string CachePath(const std::string& key) {
  const std::string dir = ColourCacheDir();
  return dir.empty() ? "" : fmt::format("{}/colour-table-{:016x}.lut", dir, util::Fnv1a64(key));
}

template <typename T>
void Put(std::string* out, T v) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));
  out->append(bytes, sizeof(T));
}

// Reads a T at *at of `data`; false when the data ends first.
template <typename T>
bool Get(const std::string& data, size_t* at, T* v) {
  if (data.size() - *at < sizeof(T)) return false;
  std::memcpy(v, data.data() + *at, sizeof(T));
  *at += sizeof(T);
  return true;
}

}  // namespace

std::string ColourCacheDir() {
  const char* off = std::getenv("FV_NO_CACHE");
  if (off != nullptr && std::string(off) != "0" && std::string(off) != "") return "";
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg != nullptr && xdg[0] == '/') return std::string(xdg) + "/fieldvision";
  const char* home = std::getenv("HOME");
  if (home != nullptr && home[0] == '/') return std::string(home) + "/.cache/fieldvision";
  return "";
}

std::optional<util::HugeBuffer> LoadCachedTable(const std::string& key, size_t size) {
  const std::string path = CachePath(key);
  if (path.empty()) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (data.compare(0, kMagicSize, kMagic) != 0) return std::nullopt;
  size_t at = kMagicSize;
  uint64_t key_size = 0, table_size = 0;
  if (!Get(data, &at, &key_size) || data.size() - at < key_size ||
      data.compare(at, key_size, key) != 0 || key_size != key.size()) {
    return std::nullopt;
  }
  at += key_size;
  if (!Get(data, &at, &table_size) || table_size != size) return std::nullopt;
  util::HugeBuffer table(size);
  size_t filled = 0;
  while (filled < size) {
    uint8_t value = 0;
    uint32_t run = 0;
    if (!Get(data, &at, &value) || !Get(data, &at, &run) || run == 0 || run > size - filled) {
      return std::nullopt;
    }
    std::memset(table.data() + filled, value, run);
    filled += run;
  }
  if (at != data.size()) return std::nullopt;
  std::error_code ec;  // used now: the last to be pruned
  fs::last_write_time(path, fs::file_time_type::clock::now(), ec);
  return table;
}

void StoreCachedTable(const std::string& key, const uint8_t* table, size_t size) {
  const std::string path = CachePath(key);
  if (path.empty() || table == nullptr) return;
  std::string out(kMagic, kMagicSize);
  Put<uint64_t>(&out, key.size());
  out += key;
  Put<uint64_t>(&out, size);
  for (size_t i = 0; i < size;) {
    size_t j = i + 1;
    while (j < size && table[j] == table[i] && j - i < 0xFFFFFFFFu) ++j;
    Put<uint8_t>(&out, table[i]);
    Put<uint32_t>(&out, static_cast<uint32_t>(j - i));
    i = j;
  }
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  if (ec) return;
  const std::string tmp = fmt::format("{}.{}.tmp", path, ::getpid());
  {
    std::ofstream f(tmp, std::ios::binary);
    f.write(out.data(), static_cast<std::streamsize>(out.size()));
    if (!f.good()) {
      f.close();
      fs::remove(tmp, ec);
      return;
    }
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return;
  }
  PruneColourCache(fs::path(path).parent_path().string(), kColourCacheFiles);
}

void PruneColourCache(const std::string& dir, size_t keep) {
  std::vector<std::pair<fs::file_time_type, fs::path>> tables;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!util::StartsWith(name, "colour-table-") || !util::EndsWith(name, ".lut")) continue;
    std::error_code time_ec;
    const fs::file_time_type t = e.last_write_time(time_ec);
    if (!time_ec) tables.emplace_back(t, e.path());
  }
  if (ec || tables.size() <= keep) return;
  std::sort(tables.begin(), tables.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  for (size_t i = keep; i < tables.size(); ++i) fs::remove(tables[i].second, ec);
}

}  // namespace fv::detect
