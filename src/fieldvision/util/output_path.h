// Output policy for every writer: refuse an output that is one of the inputs (same file by inode,
// after following symlinks), write through a symlink to its target, refuse devices and folders,
// and write to a temporary file beside the target that is renamed only on success.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace fv::util {

class CsvWriter;

// Whether `a` and `b` are one file: by inode when both exist (symlinks and hard links count), else
// by normalised absolute path.
bool SameFile(const std::string& a, const std::string& b);

// Throws fv::Error (one line, naming `what` and both paths) when `out` is the same file as one of
// `inputs`, the run's inputs and the outputs checked before it (compared with
// std::filesystem::equivalent, so symlinks and hard links count; also by weakly_canonical path
// for files that do not exist yet). Empty paths are skipped.
void CheckOutputPath(const std::string& out, const std::vector<std::string>& inputs,
                     std::string_view what = "--out");

// One list of paths from any mix of strings and vectors of strings (for CheckOutputPath).
template <typename... Paths>
std::vector<std::string> PathList(const Paths&... paths) {
  std::vector<std::string> list;
  auto add = [&list](const auto& p) {
    if constexpr (std::is_convertible_v<decltype(p), std::string>) {
      list.push_back(p);
    } else {
      list.insert(list.end(), p.begin(), p.end());
    }
  };
  (add(paths), ...);
  return list;
}

// The regular file a write to `out` should replace: `out` itself, or the final target of a
// symlink. Throws fv::Error when `out` exists and is not a regular file (device, folder, fifo).
std::string ResolveOutputPath(const std::string& out, std::string_view what = "--out");

// A folder for a run's outputs (`--draw DIR`), made with its missing parents and required empty
// (an earlier run's files would mix in, and nothing of the user's is replaced); until Keep(),
// the folders it made are removed again while empty (a failed run leaves nothing behind).
// Throws fv::Error naming `what` and the folder.
class NewFolder {
 public:
  NewFolder(const std::string& path, std::string_view what);
  ~NewFolder();
  NewFolder(const NewFolder&) = delete;
  NewFolder& operator=(const NewFolder&) = delete;
  void Keep() { keep_ = true; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::vector<std::string> made_;  // the deepest first
  bool keep_ = false;
};

// A temporary file beside the (resolved) output; Commit() renames it over the output, the
// destructor removes it when Commit() was not reached (a failed run leaves the output as it was).
class AtomicOutput {
 public:
  explicit AtomicOutput(const std::string& out, std::string_view what = "--out");
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  // Where to write.
  const std::string& temp_path() const { return temp_; }
  // The file that Commit() replaces (the symlink's target when `out` is a symlink).
  const std::string& target_path() const { return target_; }
  // Renames the temporary file over the target; throws fv::Error naming the output on failure.
  void Commit();
  // Throws `error` again with the temporary file's name replaced by the output's (a writer's
  // message names the file it wrote: the user knows the output, not the temporary file).
  [[noreturn]] void Rethrow(const std::exception& error) const;
  // Closes `csv` (written to temp_path(); a failed write is reported naming the output) and
  // commits.
  void CloseAndCommit(CsvWriter& csv);

 private:
  std::string out_;
  std::string target_;
  std::string temp_;
  bool committed_ = false;
};

// Calls `write(temp_path)` and renames the result over `out` when it returns; on an exception the
// temporary file is removed and the exception passes on.
void AtomicWrite(const std::string& out, const std::function<void(const std::string&)>& write,
                 std::string_view what = "--out");

// `text` as the whole file `out`, through AtomicWrite; throws fv::Error naming `what` and `out`
// when it cannot be written.
void WriteTextFile(const std::string& out, std::string_view text, std::string_view what);

// Removes an earlier run's file at `path` (a sidecar a new run does not write) when there is one;
// returns whether it did. Throws fv::Error "cannot remove the earlier <what> '<path>': ..." when
// it cannot.
bool RemoveEarlierFile(const std::string& path, std::string_view what);

}  // namespace fv::util
