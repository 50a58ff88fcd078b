// Where the running program is and what the install rules (CMakeLists.txt: bin/, lib/fieldvision/,
// share/fieldvision/ under one prefix) put beside it, found from /proc/self/exe so that an
// installed tree can be moved to any prefix (as COLMAP and Blender find their resources).
#pragma once

#include <filesystem>

namespace fv::util {

// The running program's file; empty when /proc/self/exe cannot be read.
std::filesystem::path ProgramPath();

// The folder holding the running program (bin/); empty when unknown.
std::filesystem::path ProgramDir();

// bin/../share/fieldvision (models/, studio/) of an installed tree; empty when unknown.
std::filesystem::path InstalledDataDir();

// bin/../lib/fieldvision (plugins) of an installed tree; empty when unknown.
std::filesystem::path InstalledPluginDir();

}  // namespace fv::util
