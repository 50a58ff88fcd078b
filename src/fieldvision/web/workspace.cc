#include "fieldvision/web/workspace.h"

#include <algorithm>
#include <charconv>
#include <limits>
#include <map>
#include <regex>
#include <system_error>

#include "fieldvision/util/strings.h"

namespace fv::web {

namespace fs = std::filesystem;

namespace {

bool Inside(const fs::path& root, const fs::path& p) {
  const fs::path rel = p.lexically_relative(root);
  if (rel.empty()) return false;
  if (rel == ".") return true;
  return *rel.begin() != "..";
}

}  // namespace

std::string FileKind(const fs::path& path) {
  const std::string ext = util::ToLower(path.extension().string());
  if (ext == ".avi" || ext == ".mp4" || ext == ".mkv" || ext == ".mov" || ext == ".webm") {
    return "video";
  }
  if (path.string().find('%') != std::string::npos) return "images";
  if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp") return "image";
  if (ext == ".yaml" || ext == ".yml") return "camera";
  if (ext == ".csv" || ext == ".txt") return "csv";
  if (ext == ".json") return "json";
  return "other";
}

Workspace::Workspace(const fs::path& root) {
  std::error_code ec;
  root_ = fs::canonical(root, ec);
  FV_REQUIRE(!ec && fs::is_directory(root_), "studio folder '{}' is not a folder", root.string());
}

fs::path Workspace::Resolve(const std::string& path, bool must_exist) const {
  if (path.empty()) throw HttpError(400, "no path given");
  if (path.find('\0') != std::string::npos || path.find('\n') != std::string::npos) {
    throw HttpError(400, "path has control characters");
  }
  fs::path p(path);
  if (p.is_relative()) p = root_ / p;
  std::error_code ec;
  fs::path c = fs::weakly_canonical(p, ec);
  if (ec) throw HttpError(400, "path '" + path + "' cannot be resolved");
  if (!Inside(root_, c)) throw HttpError(403, "path '" + path + "' is outside the studio folder");
  const bool pattern = c.filename().string().find('%') != std::string::npos;
  if (must_exist) {
    if (pattern) {
      if (!fs::is_directory(c.parent_path())) {
        throw HttpError(404, "folder of '" + path + "' does not exist");
      }
    } else if (!fs::exists(c)) {
      throw HttpError(404, "file '" + path + "' does not exist");
    }
  }
  return c;
}

fs::path Workspace::ResolveOutput(const std::string& path,
                                  const std::vector<std::string>& extensions) const {
  if (!extensions.empty()) {
    const std::string ext = util::ToLower(fs::path(path).extension().string());
    if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) {
      std::string names;
      for (const std::string& e : extensions) names += (names.empty() ? "" : " or ") + e;
      throw HttpError(400, "output '" + path + "' must end in " + names);
    }
  }
  fs::path c = Resolve(path, false);
  if (c == root_) throw HttpError(400, "output path '" + path + "' is the studio folder");
  if (!fs::is_directory(c.parent_path())) {
    throw HttpError(404, "folder of output '" + path + "' does not exist");
  }
  if (fs::is_directory(c)) throw HttpError(400, "output '" + path + "' is a folder");
  return c;
}

std::string Workspace::Relative(const fs::path& absolute) const {
  return absolute.lexically_relative(root_).generic_string();
}

nlohmann::json Workspace::ListFiles(size_t max_files) const {
  nlohmann::json files = nlohmann::json::array();
  // Folders whose files are numbered images: listed as one pattern.
  static const std::regex kNumbered(R"(^(\d+)\.(png|jpg|jpeg|bmp)$)", std::regex::icase);
  // folder -> (pattern, its files)
  std::map<fs::path, std::pair<std::string, std::vector<fs::path>>> sequences;
  std::vector<fs::path> paths;
  std::error_code ec;
  fs::recursive_directory_iterator it(root_, fs::directory_options::skip_permission_denied, ec);
  for (; !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    const fs::path& p = it->path();
    const std::string name = p.filename().string();
    if (it->is_directory(ec)) {
      // Hidden folders, npm's and build trees (CMake's, whatever their name): not the user's data.
      if (name.empty() || name[0] == '.' || name == "node_modules" ||
          fs::exists(p / "CMakeCache.txt", ec)) {
        it.disable_recursion_pending();
      }
      continue;
    }
    if (!it->is_regular_file(ec)) continue;
    std::smatch m;
    if (std::regex_match(name, m, kNumbered)) {
      auto& s = sequences[p.parent_path()];
      if (s.first.empty()) {
        s.first = "%0" + std::to_string(m[1].length()) + "d." + m[2].str();
      }
      s.second.push_back(p);
      continue;
    }
    paths.push_back(p);
    if (paths.size() >= max_files) break;
  }
  for (const auto& [folder, s] : sequences) {
    // One numbered image is an image; numbers with gaps are photos (a video's frames are
    // numbered without gaps, and a pattern over gaps opens none of them).
    long long lo = std::numeric_limits<long long>::max(), hi = -1;
    for (const fs::path& p : s.second) {
      const std::string stem = p.stem().string();
      long long n = 0;
      if (std::from_chars(stem.data(), stem.data() + stem.size(), n).ec != std::errc()) {
        n = std::numeric_limits<long long>::max() / 2;  // too long a number: no sequence
      }
      lo = std::min(lo, n);
      hi = std::max(hi, n);
    }
    if (s.second.size() < 2 || hi - lo + 1 != static_cast<long long>(s.second.size())) {
      paths.insert(paths.end(), s.second.begin(), s.second.end());
      continue;
    }
    files.push_back(
        {{"path", Relative(folder / s.first)}, {"size", s.second.size()}, {"kind", "images"}});
  }
  std::sort(paths.begin(), paths.end());
  for (const auto& p : paths) {
    std::error_code size_ec;
    const auto size = fs::file_size(p, size_ec);
    files.push_back({{"path", Relative(p)}, {"size", size_ec ? 0 : size}, {"kind", FileKind(p)}});
  }
  return files;
}

}  // namespace fv::web
