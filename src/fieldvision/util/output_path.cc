#include "fieldvision/util/output_path.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::util {
namespace fs = std::filesystem;

bool SameFile(const std::string& a_name, const std::string& b_name) {
  const fs::path a = a_name, b = b_name;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) {
    const bool same = fs::equivalent(a, b, ec);
    if (!ec) return same;
  }
  const fs::path ca = fs::weakly_canonical(a, ec);
  if (ec) return false;
  const fs::path cb = fs::weakly_canonical(b, ec);
  if (ec) return false;
  return ca == cb;
}

void CheckOutputPath(const std::string& out, const std::vector<std::string>& inputs,
                     std::string_view what) {
  if (out.empty()) return;
  for (const std::string& in : inputs) {
    if (in.empty()) continue;
    FV_REQUIRE(
        !SameFile(out, in),
        "{} '{}' is the same file as '{}' (read or written by this run): choose another output",
        what, out, in);
  }
}

std::string ResolveOutputPath(const std::string& out, std::string_view what) {
  FV_REQUIRE(!out.empty(), "{}: empty output path", what);
  std::error_code ec;
  fs::path target = out;
  if (fs::is_symlink(fs::symlink_status(target, ec))) {
    // Write through the link: replace its final target, keep the link.
    target = fs::weakly_canonical(target, ec);
    FV_REQUIRE(!ec, "{} '{}': cannot follow the link: {}", what, out, ec.message());
  }
  const fs::file_status st = fs::status(target, ec);
  if (fs::exists(st)) {
    FV_REQUIRE(fs::is_regular_file(st), "{} '{}' exists and is not a regular file", what, out);
  }
  // Writers would otherwise fail on the temporary name, which the user never gave.
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  FV_REQUIRE(fs::is_directory(folder, ec), "{} '{}': folder '{}' does not exist", what, out,
             folder.string());
  return target.string();
}

AtomicOutput::AtomicOutput(const std::string& out, std::string_view what)
    : out_(out), target_(ResolveOutputPath(out, what)) {
  // Beside the target (same file system: rename is atomic), unique per process and write (two
  // studio saves of one file at once), keeping the extension that writers such as
  // cv::VideoWriter and cv::imwrite choose the format by.
  const fs::path t = target_;
  static std::atomic<long long> count{0};
  temp_ = (t.parent_path() / (t.stem().string() + "." + std::to_string(::getpid()) + "-" +
                              std::to_string(count++) + ".part" + t.extension().string()))
              .string();
  // Made and removed at once: a folder that takes no file is named now, with the output's name
  // (a writer's error names the temporary file, which the user never gave).
  {
    std::ofstream probe(temp_, std::ios::binary);
    FV_REQUIRE(probe.good(), "{} '{}': cannot write a file in folder '{}'", what, out,
               t.parent_path().empty() ? std::string(".") : t.parent_path().string());
  }
  std::error_code ec;
  fs::remove(temp_, ec);
}

AtomicOutput::~AtomicOutput() {
  if (committed_) return;
  std::error_code ec;
  fs::remove(temp_, ec);
}

void AtomicOutput::Commit() {
  std::error_code ec;
  FV_REQUIRE(fs::exists(temp_, ec), "cannot write '{}': nothing was written", out_);
  fs::rename(temp_, target_, ec);
  FV_REQUIRE(!ec, "cannot write '{}': {}", out_, ec.message());
  committed_ = true;
}

void AtomicOutput::Rethrow(const std::exception& error) const {
  throw Error(ReplaceAll(error.what(), temp_, out_));
}

void AtomicOutput::CloseAndCommit(CsvWriter& csv) {
  try {
    csv.Close();
  } catch (const Error& e) {
    Rethrow(e);
  }
  Commit();
}

void AtomicWrite(const std::string& out, const std::function<void(const std::string&)>& write,
                 std::string_view what) {
  AtomicOutput file(out, what);
  try {
    write(file.temp_path());
  } catch (const Error& e) {
    file.Rethrow(e);
  }
  file.Commit();
}

void WriteTextFile(const std::string& out, std::string_view text, std::string_view what) {
  AtomicWrite(
      out,
      [&](const std::string& temp_path) {
        std::ofstream f(temp_path, std::ios::binary);
        f << text;
        f.close();
        FV_REQUIRE(!f.fail(), "cannot write {} '{}'", what, out);
      },
      what);
}

NewFolder::NewFolder(const std::string& path, std::string_view what) : path_(path) {
  std::error_code ec;
  FV_REQUIRE(!path.empty(), "{}: no folder given", what);
  FV_REQUIRE(!fs::exists(path, ec) || fs::is_directory(path, ec),
             "{}: '{}' exists and is not a folder", what, path);
  for (fs::path p = fs::absolute(path, ec); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    made_.push_back(p.string());
    if (p == p.parent_path()) break;
  }
  fs::create_directories(path, ec);
  FV_REQUIRE(fs::is_directory(path, ec), "{}: cannot make folder '{}'", what, path);
  FV_REQUIRE(fs::is_empty(path, ec) && !ec,
             "{}: folder '{}' is not empty (an earlier run's files would mix with these, or be "
             "replaced); name a new folder",
             what, path);
}

NewFolder::~NewFolder() {
  if (keep_) return;
  std::error_code ec;
  for (const std::string& p : made_) {
    if (!fs::remove(p, ec)) break;  // only empty folders go
  }
}

bool RemoveEarlierFile(const std::string& path, std::string_view what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  FV_REQUIRE(std::filesystem::remove(path, ec), "cannot remove the earlier {} '{}': {}", what, path,
             ec.message());
  return true;
}

}  // namespace fv::util
