#include "fieldvision/io/video_writer.h"

#include <cmath>
#include <filesystem>

#include <unistd.h>

#include <fmt/format.h>
#include <opencv2/core/utils/logger.hpp>

#include "fieldvision/codecs/codecs.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

namespace fv::io {
namespace fs = std::filesystem;

namespace {

// Opens a writer with OpenCV's log quiet (a missing encoder is an expected outcome here).
bool TryOpen(cv::VideoWriter* w, const std::string& path, int fourcc, double fps, cv::Size size) {
  const auto level = cv::utils::logging::getLogLevel();
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  bool ok = false;
  try {
    ok = codecs::OpenVideoWriter(w, path, cv::CAP_FFMPEG, fourcc, fps, size) && w->isOpened();
  } catch (const cv::Exception&) {
    ok = false;
  }
  cv::utils::logging::setLogLevel(level);
  return ok;
}

}  // namespace

bool H264Available() {
  static const bool kAvailable = [] {
    const fs::path p = fs::temp_directory_path() / fmt::format("fv_h264_probe_{}.mp4", ::getpid());
    const auto w = codecs::NewVideoWriter();
    bool ok = TryOpen(w.get(), p.string(), codecs::FourCc('a', 'v', 'c', '1'), 10, {64, 64});
    if (ok) {
      w->write(cv::Mat(64, 64, CV_8UC3, cv::Scalar(0, 0, 0)));
      w->release();
      std::error_code ec;
      ok = fs::file_size(p, ec) > 0 && !ec;
    }
    std::error_code ec;
    fs::remove(p, ec);
    return ok;
  }();
  return kAvailable;
}

bool IsVideoName(const std::string& path) {
  const std::string ext = util::ToLower(fs::path(path).extension().string());
  return ext == ".mp4" || ext == ".avi" || ext == ".mkv";
}

void CheckVideoPath(const std::string& path, std::string_view what) {
  const std::string ext = util::ToLower(fs::path(path).extension().string());
  FV_REQUIRE(IsVideoName(path), "{} '{}': a video's name ends in .mp4, .avi or .mkv{}", what, path,
             ext.empty() ? "" : fmt::format(" (not {})", ext));
}

std::string FallbackVideoPath(const std::string& path) {
  if (util::ToLower(fs::path(path).extension().string()) != ".mp4") return path;
  return fs::path(path).replace_extension(".avi").string();
}

void CheckVideoOutput(const std::string& path, const std::vector<std::string>& inputs,
                      std::string_view what) {
  CheckVideoPath(path, what);
  util::CheckOutputPath(path, inputs, what);
  util::CheckOutputPath(FallbackVideoPath(path), inputs, what);
  util::ResolveOutputPath(path, what);
}

PlayableVideoWriter::PlayableVideoWriter(const std::string& path, double fps, cv::Size size,
                                         std::string_view what)
    : writer_(codecs::NewVideoWriter()), size_(size) {
  CheckVideoPath(path, what);
  FV_REQUIRE(fps > 0 && std::isfinite(fps), "{} '{}': frame rate must be positive (got {})", what,
             path, fps);
  FV_REQUIRE(size.width > 0 && size.height > 0, "{} '{}': empty frame size", what, path);
  path_ = path;
  const bool mp4 = FallbackVideoPath(path) != path;
  if (mp4 && H264Available()) {
    out_ = std::make_unique<util::AtomicOutput>(path_, what);
    if (TryOpen(writer_.get(), out_->temp_path(), codecs::FourCc('a', 'v', 'c', '1'), fps, size)) {
      codec_ = "H.264";
      return;
    }
    out_.reset();
  }
  if (mp4) {
    path_ = FallbackVideoPath(path);
    note_ = fmt::format(
        "OpenCV's FFmpeg has no H.264 encoder here: wrote Motion-JPEG to '{}' instead (browsers do "
        "not play it; VLC or ffplay do)",
        path_);
  }
  // Beside the path (through a symlink to its target), unique per process, renamed at Close().
  out_ = std::make_unique<util::AtomicOutput>(path_, what);
  FV_REQUIRE(
      TryOpen(writer_.get(), out_->temp_path(), codecs::FourCc('M', 'J', 'P', 'G'), fps, size),
      "cannot write video '{}' (folder missing or not writable?)", path_);
  codec_ = "MJPG";
}

PlayableVideoWriter::~PlayableVideoWriter() {
  if (!closed_) writer_->release();  // out_ then removes the temporary file
}

void PlayableVideoWriter::Write(const cv::Mat& bgr) {
  FV_REQUIRE(bgr.size() == size_ && bgr.type() == CV_8UC3,
             "video '{}': frame {} is {}x{}, the video {}x{}", path_, frames_, bgr.cols, bgr.rows,
             size_.width, size_.height);
  writer_->write(bgr);
  ++frames_;
}

void PlayableVideoWriter::Close() {
  if (closed_) return;
  writer_->release();
  closed_ = true;
  out_->Commit();  // throws naming path_; the temporary file goes with out_
}

}  // namespace fv::io
