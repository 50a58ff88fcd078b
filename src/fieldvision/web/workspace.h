// The studio's working folder: every path a request names is resolved inside the folder the
// server was started in (symbolic links followed), and anything else is refused with an HTTP
// status and a one-line message (HttpError), so no file outside it is ever read or written.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldvision/util/error.h"

namespace fv::web {

// A request the server refuses: HTTP status (4xx) and a one-line message.
class HttpError : public fv::Error {
 public:
  HttpError(int status, const std::string& message) : fv::Error(message), status_(status) {}
  int status() const { return status_; }

 private:
  int status_;
};

class Workspace {
 public:
  // `root` must be an existing folder; it is made canonical. Throws fv::Error naming it.
  explicit Workspace(const std::filesystem::path& root);
  const std::filesystem::path& root() const { return root_; }

  // A path named by a request (relative to the root, or absolute inside it): the canonical
  // absolute path. Throws HttpError 400 (empty), 403 (outside the folder) or 404 (`must_exist`
  // and absent). An image pattern (dir/%05d.png) must have its folder inside.
  std::filesystem::path Resolve(const std::string& path, bool must_exist = true) const;
  // For writing: the parent folder must exist inside the root; throws 400/403/404 as Resolve,
  // and 400 when the name does not end in one of `extensions` (any case; empty: any name), so
  // that a save never replaces a video or an image with a camera or zones file.
  std::filesystem::path ResolveOutput(const std::string& path,
                                      const std::vector<std::string>& extensions = {}) const;
  // The path relative to the root, with '/' separators.
  std::string Relative(const std::filesystem::path& absolute) const;

  // Files under the root (hidden folders, node_modules and build* folders skipped), at most
  // `max_files`, sorted: [{path, size, kind}] with kind video, images, image, camera, csv, json,
  // other. Image sequences (folders of numbered images) are listed once as "dir/%05d.png".
  nlohmann::json ListFiles(size_t max_files = 5000) const;

 private:
  std::filesystem::path root_;
};

// Kind of a file by its name: "video", "image", "camera" (yaml), "csv", "json" or "other".
std::string FileKind(const std::filesystem::path& path);

}  // namespace fv::web
