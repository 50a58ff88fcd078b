// The colour tables' disk cache: a shared table is written once and read back equal; a damaged
// file, a table that disagrees with its spec (written by other code) and a file of another size
// are rebuilt or refused; FV_NO_CACHE=1 writes nothing.
#include "fieldvision/detect/colour_cache.h"

#include <sys/stat.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "fieldvision/detect/colour.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

namespace fs = std::filesystem;

// Points XDG_CACHE_HOME at a fresh folder (and clears FV_NO_CACHE) while in scope.
class CacheHome {
 public:
  explicit CacheHome(const std::string& name)
      : dir_(fv::testing::TempDir() + "/" + name),
        old_xdg_(Get("XDG_CACHE_HOME")),
        old_off_(Get("FV_NO_CACHE")) {
    fs::remove_all(dir_);
    ::setenv("XDG_CACHE_HOME", dir_.c_str(), 1);
    ::unsetenv("FV_NO_CACHE");
  }
  ~CacheHome() {
    Restore("XDG_CACHE_HOME", old_xdg_);
    Restore("FV_NO_CACHE", old_off_);
  }
  CacheHome(const CacheHome&) = delete;
  CacheHome& operator=(const CacheHome&) = delete;
  std::vector<fs::path> Files() const {
    std::vector<fs::path> files;
    if (fs::exists(dir_ + "/fieldvision")) {
      for (const auto& e : fs::directory_iterator(dir_ + "/fieldvision")) files.push_back(e.path());
    }
    return files;
  }

 private:
  static std::optional<std::string> Get(const char* name) {
    const char* v = std::getenv(name);
    return v ? std::optional<std::string>(v) : std::nullopt;
  }
  static void Restore(const char* name, const std::optional<std::string>& v) {
    if (v) {
      ::setenv(name, v->c_str(), 1);
    } else {
      ::unsetenv(name);
    }
  }
  std::string dir_;
  std::optional<std::string> old_xdg_, old_off_;
};

ino_t Inode(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? st.st_ino : 0;
}

bool SameTable(const ColourTable& a, const ColourTable& b) {
  const size_t n = size_t(1) << (3 * a.bits_per_channel());
  return a.bits_per_channel() == b.bits_per_channel() && std::memcmp(a.data(), b.data(), n) == 0;
}

TEST(ColourCache, ASharedTableIsWrittenOnceAndReadBackEqual) {
  const CacheHome home("colour_cache_roundtrip");
  const ColourSpec spec = PresetColourSpec("orange");
  const ColourTable built(spec, 6);
  { const auto first = ColourTable::Shared(spec, 6); }  // built and stored
  ASSERT_EQ(home.Files().size(), 1u);
  const std::string file = home.Files()[0];
  const ino_t written = Inode(file);
  fs::last_write_time(file, fs::last_write_time(file) - std::chrono::hours(1));
  const auto an_hour_ago = fs::last_write_time(file);
  const auto second = ColourTable::Shared(spec, 6);  // read back
  EXPECT_TRUE(SameTable(*second, built));
  EXPECT_EQ(Inode(file), written);                    // not written again
  EXPECT_GT(fs::last_write_time(file), an_hour_ago);  // marked used
  EXPECT_TRUE(second->AgreesWithSpec(4096));
}

TEST(ColourCache, DamagedOrForeignFilesAreRebuilt) {
  const CacheHome home("colour_cache_damaged");
  const ColourSpec spec = PresetColourSpec("yellow");
  const ColourTable built(spec, 5);
  { const auto first = ColourTable::Shared(spec, 5); }
  ASSERT_EQ(home.Files().size(), 1u);
  const fs::path file = home.Files()[0];
  // Cut short: not a table; the shared table is rebuilt (and stored again).
  fs::resize_file(file, fs::file_size(file) / 2);
  {
    const auto again = ColourTable::Shared(spec, 5);
    EXPECT_TRUE(SameTable(*again, built));
  }
  EXPECT_GT(fs::file_size(file), 0u);
  // Another spec's table stored under this spec's key reads back whole but disagrees with the
  // spec: rebuilt.
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  uint64_t key_size = 0;
  ASSERT_GT(bytes.size(), 15u);
  std::memcpy(&key_size, bytes.data() + 7, 8);  // after "FVLUT1\n"
  const std::string key = bytes.substr(15, key_size);
  const ColourTable other(PresetColourSpec("blue"), 5);
  StoreCachedTable(key, other.data(), size_t(1) << 15);
  ASSERT_TRUE(LoadCachedTable(key, size_t(1) << 15).has_value());
  const auto rebuilt = ColourTable::Shared(spec, 5);
  EXPECT_TRUE(SameTable(*rebuilt, built));
  // The wrong size is no table.
  EXPECT_FALSE(LoadCachedTable(key, size_t(1) << 18).has_value());
  EXPECT_FALSE(LoadCachedTable("no such key", size_t(1) << 15).has_value());
}

TEST(ColourCache, PruningKeepsTheTablesUsedLast) {
  const std::string dir = fv::testing::TempDir() + "/colour_cache_prune";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto now = fs::file_time_type::clock::now();
  std::vector<std::string> tables;
  for (int i = 0; i < 20; ++i) {
    tables.push_back(fmt::format("{}/colour-table-{:016x}.lut", dir, i));
    std::ofstream(tables.back()) << "t";
    fs::last_write_time(tables.back(), now - std::chrono::minutes(20 - i));  // 19 used last
  }
  const std::string other = dir + "/notes.txt";
  std::ofstream(other) << "kept";
  fs::last_write_time(other, now - std::chrono::hours(5));
  PruneColourCache(dir, 16);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(fs::exists(tables[i]), i >= 4) << tables[i];
  EXPECT_TRUE(fs::exists(other));
  PruneColourCache(dir + "/missing", 16);  // no folder: nothing to do, no error
}

TEST(ColourCache, NoCacheWritesNothing) {
  const CacheHome home("colour_cache_off");
  ::setenv("FV_NO_CACHE", "1", 1);
  EXPECT_EQ(ColourCacheDir(), "");
  const auto table = ColourTable::Shared(PresetColourSpec("pink"), 5);
  EXPECT_TRUE(table->AgreesWithSpec(256));
  EXPECT_TRUE(home.Files().empty());
}

}  // namespace
}  // namespace fv::detect
