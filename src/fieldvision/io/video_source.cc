#include "fieldvision/io/video_source.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>

#include <fmt/format.h>

#include "fieldvision/camera/frame_size.h"
#include "fieldvision/io/frame_source.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::io {
namespace {

namespace fs = std::filesystem;

// Glob with '*' and '?' in the file name part only.
std::vector<std::string> Glob(const std::string& spec) {
  const fs::path p(spec);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::string re;
  for (char c : p.filename().string()) {
    if (c == '*') {
      re += ".*";
    } else if (c == '?') {
      re += ".";
    } else if (std::isalnum(static_cast<unsigned char>(c))) {
      re += c;
    } else {
      re += std::string("\\") + c;
    }
  }
  std::vector<std::string> out;
  if (!fs::is_directory(dir)) return out;
  const std::regex pattern(re);
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file() && std::regex_match(e.path().filename().string(), pattern)) {
      out.push_back(e.path().string());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// VideoSource's reading, done by a frame source (frame_source.h).
class FrameSourceVideo : public VideoSource {
 public:
  FrameSourceVideo(const std::string& spec, std::unique_ptr<FrameSource> source)
      : source_(std::move(source)) {
    spec_ = spec;
    const cv::Size size = source_->FrameSize();
    width_ = size.width;
    height_ = size.height;
    fps_ = source_->fps();
    rate_known_ = source_->rate_known();
    const long long n = source_->FrameCount();
    frame_count_ = n > 0 ? static_cast<int>(n) : -1;
    live_ = source_->live();
  }
  std::string frames_note() const override { return source_->FramesNote(); }
  bool Read(Frame& frame) override {
    long long index = 0;
    if (!source_->Read(&frame.bgr, &index, &frame.time_s)) return false;
    FV_REQUIRE(frame.bgr.cols == width_ && frame.bgr.rows == height_,
               "video '{}': frame {} is {}x{}, the first frame {}x{}", spec_, next_index_,
               frame.bgr.cols, frame.bgr.rows, width_, height_);
    frame.index = next_index_++;
    return true;
  }

 private:
  std::unique_ptr<FrameSource> source_;
};

}  // namespace

void VideoSourceOptions::Check() const {
  FV_REQUIRE(std::isfinite(fps) && fps >= 0, "VideoSourceOptions.fps must be >= 0 (got {})", fps);
}

void CheckEndOfStream(const std::string& path, long long frames_read, long long frames_announced) {
  // Containers without a frame index give an estimate (duration x rate): a frame or two of slack.
  const long long slack = std::max(1LL, frames_announced / 1000);
  FV_REQUIRE(frames_announced <= 0 || frames_read + slack >= frames_announced,
             "video '{}' ends after {} of the {} frames its header announces (truncated or "
             "damaged from frame {}; --max-frames {} uses the frames before it)",
             path, frames_read, frames_announced, frames_read, frames_read);
}

bool IsImageFile(const std::string& path) {
  const std::string ext = util::ToLower(fs::path(path).extension().string());
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" ||
         ext == ".tiff" || ext == ".pgm" || ext == ".ppm" || ext == ".webp";
}

namespace {

// A printf pattern with one integer field (dir/%05d.png): a camera's numbered frames.
bool IsFramePattern(const std::string& spec) {
  // A field width of at most two digits: "%999999999d" made each name a gigabyte of padding
  // for snprintf to count (seconds per name, a thousand names tried).
  static const std::regex kOneIntField(R"([^%]*%0?[0-9]{0,2}d[^%]*)");
  return spec.find('%') != std::string::npos && std::regex_match(spec, kOneIntField);
}

}  // namespace

bool IsStillImageInput(const std::string& spec) {
  std::error_code ec;
  if (fs::is_directory(spec, ec)) return true;
  if (fs::is_regular_file(spec, ec)) return IsImageFile(spec);
  return !IsFramePattern(spec) && !ListImageSequence(spec).empty();
}

std::vector<std::string> ListImageSequence(const std::string& spec) {
  std::vector<std::string> files;
  if (fs::is_regular_file(spec)) {
    if (IsImageFile(spec)) files.push_back(spec);  // one image: a sequence of one
    return files;
  }
  if (spec.find('%') != std::string::npos) {
    // printf pattern with one integer field (%d, %5d, %05d): frames from the first number of
    // 0..1000 that names a file (as OpenCV's image reader starts) upwards until the first
    // missing number.
    if (!IsFramePattern(spec)) return {};
    auto name_of = [&](int i) {
      std::vector<char> buf(spec.size() + 128);
      std::snprintf(buf.data(), buf.size(), spec.c_str(), i);
      return std::string(buf.data());
    };
    constexpr int kLastStart = 1000;
    int start = 0;
    while (start <= kLastStart && !fs::is_regular_file(name_of(start))) ++start;
    if (start > kLastStart) return files;
    int end = start;
    for (;; ++end) {
      const std::string name = name_of(end);
      if (!fs::is_regular_file(name)) break;
      files.push_back(name);
    }
    // A gap would silently cut the clip short (and pair the frames after it with other cameras'
    // wrong frames): a missing frame is an error when the sequence goes on soon after it.
    constexpr int kGapProbe = 1000;
    for (int i = end + 1; i <= end + kGapProbe; ++i) {
      FV_REQUIRE(!fs::is_regular_file(name_of(i)),
                 "image sequence '{}': frame '{}' is missing (the sequence goes on at '{}')", spec,
                 name_of(end), name_of(i));
    }
    return files;
  }
  if (spec.find('*') != std::string::npos || spec.find('?') != std::string::npos) {
    return Glob(spec);
  }
  if (fs::is_directory(spec)) {
    for (const auto& e : fs::directory_iterator(spec)) {
      if (e.is_regular_file() && IsImageFile(e.path().string())) files.push_back(e.path().string());
    }
    std::sort(files.begin(), files.end());
  }
  return files;
}

std::unique_ptr<VideoSource> VideoSource::Open(const std::string& spec,
                                               const VideoSourceOptions& options) {
  options.Check();
  FV_REQUIRE(!spec.empty(), "empty video name");
  // Image sequences at options.fps (0: a scene.json's, else 30); video files at their container's
  // rate and times.
  const bool sequence = !fs::is_regular_file(spec) &&
                        (spec.find_first_of("%*?") != std::string::npos || fs::is_directory(spec));
  FrameSourceOptions so;
  if (sequence) {
    so.fps = options.fps;
    FV_REQUIRE(!ListImageSequence(spec).empty(), "image sequence '{}' matches no image file", spec);
  } else if (!util::StartsWith(spec, "camera:") && spec.find(':') == std::string::npos) {
    FV_REQUIRE(fs::exists(spec), "video '{}' does not exist", spec);
    so.time = TimeSource::kContainer;
    // Motion-JPEG decoded by libjpeg-turbo, as `ball` decodes it (OpenCV's FFmpeg reader
    // upsamples chroma differently): detect, eval detect and ball see the same pixels.
    so.encoded = true;
  }
  return std::make_unique<FrameSourceVideo>(spec, OpenFrameSource(spec, so));
}

std::string VideoSource::FitCamera(camera::Camera& camera, const std::string& camera_file) const {
  return camera::FitCameraToFrames(camera, fmt::format("camera file '{}'", camera_file), width_,
                                   height_, fmt::format("video '{}'", spec_));
}

}  // namespace fv::io
