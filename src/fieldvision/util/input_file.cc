#include "fieldvision/util/input_file.h"

#include <filesystem>

#include "fieldvision/util/error.h"

namespace fv::util {

void RequireInputFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  FV_REQUIRE(!std::filesystem::is_directory(path, ec), "{} '{}' is a folder, not a file", what,
             path);
  FV_REQUIRE(std::filesystem::exists(path, ec), "{} '{}' does not exist", what, path);
}

}  // namespace fv::util
