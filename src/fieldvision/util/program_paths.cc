#include "fieldvision/util/program_paths.h"

#include <system_error>

namespace fv::util {

namespace fs = std::filesystem;

fs::path ProgramPath() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe;
}

fs::path ProgramDir() { return ProgramPath().parent_path(); }

fs::path InstalledDataDir() {
  const fs::path bin = ProgramDir();
  return bin.empty() ? fs::path() : bin.parent_path() / "share" / "fieldvision";
}

fs::path InstalledPluginDir() {
  const fs::path bin = ProgramDir();
  return bin.empty() ? fs::path() : bin.parent_path() / "lib" / "fieldvision";
}

}  // namespace fv::util
