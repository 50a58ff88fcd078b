// Input files: one check before a reader opens a path, so that a missing file or a folder gets a
// one-line error naming the input instead of the reader's "cannot open" or "empty".
#pragma once

#include <string>

namespace fv::util {

// Throws fv::Error "{what} '{path}' does not exist" or "... is a folder, not a file" (a folder
// opened as a file reads as empty: "no header", "no rows").
void RequireInputFile(const std::string& path, const std::string& what);

}  // namespace fv::util
