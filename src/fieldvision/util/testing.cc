#include "fieldvision/util/testing.h"

#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>

namespace fv::testing {

uint64_t TestSeed(uint64_t fallback) {
  if (const char* s = std::getenv("FV_TEST_SEED")) return std::strtoull(s, nullptr, 10);
  return fallback;
}

std::string TempDir() {
  namespace fs = std::filesystem;
  const char* base = std::getenv("FV_TEST_TMP");
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string name =
      info ? fmt::format("{}.{}", info->test_suite_name(), info->name()) : "test";
  fs::path dir = fs::path(base ? base : fs::temp_directory_path().string()) / "fieldvision" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string SharedDataDir() {
#ifdef FV_SHARED_DATA_DIR
  std::filesystem::path p(FV_SHARED_DATA_DIR);
  if (std::filesystem::exists(p)) return std::filesystem::canonical(p).string();
#endif
  return "";
}

double SlowdownFactor() {
#if defined(__SANITIZE_ADDRESS__)
  return 10.0;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  return 10.0;
#else
  return 1.0;
#endif
#else
  return 1.0;
#endif
}

}  // namespace fv::testing
