#include "fieldvision/io/video_source.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <regex>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv {
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

class ImageSequenceSource : public VideoSource {
 public:
  ImageSequenceSource(const std::string& spec, std::vector<std::string> files, double fps)
      : files_(std::move(files)) {
    spec_ = spec;
    fps_ = fps;
    frame_count_ = static_cast<int>(files_.size());
    const cv::Mat first = cv::imread(files_.front(), cv::IMREAD_COLOR);
    FV_REQUIRE(!first.empty(), "image sequence '{}': cannot read its first image '{}'", spec,
               files_.front());
    width_ = first.cols;
    height_ = first.rows;
  }

  bool Read(Frame& frame) override {
    if (next_index_ >= frame_count_) return false;
    const std::string& file = files_[next_index_];
    frame.bgr = cv::imread(file, cv::IMREAD_COLOR);
    FV_REQUIRE(!frame.bgr.empty(), "image sequence '{}': frame {} ('{}') cannot be read", spec_,
               next_index_, file);
    FV_REQUIRE(frame.bgr.cols == width_ && frame.bgr.rows == height_,
               "image sequence '{}': frame {} ('{}') is {}x{}, the first frame {}x{}", spec_,
               next_index_, file, frame.bgr.cols, frame.bgr.rows, width_, height_);
    frame.index = next_index_;
    frame.time_s = next_index_ / fps_;
    ++next_index_;
    return true;
  }

 private:
  std::vector<std::string> files_;
};

class CaptureSource : public VideoSource {
 public:
  CaptureSource(const std::string& spec, double fallback_fps) {
    spec_ = spec;
    if (StartsWith(spec, "camera:")) {
      const int device =
          static_cast<int>(ParseInt(spec.substr(7), "camera device in '" + spec + "'"));
      live_ = true;
      cap_.open(device);
      FV_REQUIRE(cap_.isOpened(), "cannot open live camera {} ('{}')", device, spec);
      start_ = std::chrono::steady_clock::now();
    } else {
      FV_REQUIRE(fs::exists(spec), "video '{}' does not exist", spec);
      FV_REQUIRE(fs::is_regular_file(spec), "video '{}' is not a file", spec);
      FV_REQUIRE(OpenVideoFile(cap_, spec),
                 "video '{}' cannot be opened (not a video OpenCV can decode?)", spec);
      frame_count_ = static_cast<int>(cap_.get(cv::CAP_PROP_FRAME_COUNT));
      if (frame_count_ <= 0) frame_count_ = -1;
    }
    fps_ = cap_.get(cv::CAP_PROP_FPS);
    if (!(fps_ > 0 && fps_ < 10000)) fps_ = fallback_fps;
    // Decode the first frame now so a file with a valid header but no decodable frame fails here.
    FV_REQUIRE(cap_.read(pending_) && !pending_.empty(), "video '{}' has no decodable frame", spec);
    pending_time_s_ = TimeOfLastRead();
    width_ = pending_.cols;
    height_ = pending_.rows;
    has_pending_ = true;
  }

  bool Read(Frame& frame) override {
    if (has_pending_) {
      frame.bgr = pending_;
      frame.time_s = pending_time_s_;
      has_pending_ = false;
    } else {
      cv::Mat m;
      bool ok = false;
      try {
        ok = cap_.read(m) && !m.empty();
      } catch (const cv::Exception&) {
        ok = false;
      }
      if (!ok) {
        CheckEndOfStream(spec_, next_index_, frame_count_);
        return false;
      }
      FV_REQUIRE(m.cols == width_ && m.rows == height_,
                 "video '{}': frame {} is {}x{}, the first frame {}x{}", spec_, next_index_, m.cols,
                 m.rows, width_, height_);
      frame.bgr = m;
      frame.time_s = TimeOfLastRead();
    }
    frame.index = next_index_++;
    return true;
  }

 private:
  double TimeOfLastRead() {
    if (live_) {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }
    const double ms = cap_.get(cv::CAP_PROP_POS_MSEC);
    // Some backends report the position after the frame; frame / fps is the robust fallback.
    const double by_index = next_index_ / fps_;
    if (!(ms >= 0) || std::abs(ms / 1000.0 - by_index) > 2.0 / fps_) return by_index;
    return ms / 1000.0;
  }

  cv::VideoCapture cap_;
  cv::Mat pending_;
  double pending_time_s_ = 0.0;
  bool has_pending_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

void VideoSourceOptions::Check() const { CheckPositive(fps, "VideoSourceOptions.fps"); }

bool OpenVideoFile(cv::VideoCapture& capture, const std::string& path) {
  // A file that exists is a video even when its name has a '%' (100%.avi).
  const int api = path.find('%') != std::string::npos && !fs::is_regular_file(path)
                      ? cv::CAP_IMAGES
                      : cv::CAP_FFMPEG;
  try {
    return capture.open(path, api) && capture.isOpened();
  } catch (const cv::Exception&) {
    return false;
  }
}

void CheckEndOfStream(const std::string& path, long long frames_read, long long frames_announced) {
  // Containers without a frame index give an estimate (duration x rate): a frame or two of slack.
  const long long slack = std::max(1LL, frames_announced / 1000);
  FV_REQUIRE(frames_announced <= 0 || frames_read + slack >= frames_announced,
             "video '{}' ends after {} of the {} frames its header announces (truncated or "
             "damaged from frame {})",
             path, frames_read, frames_announced, frames_read);
}

bool IsImageFile(const std::string& path) {
  const std::string ext = ToLower(fs::path(path).extension().string());
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" ||
         ext == ".tiff" || ext == ".pgm" || ext == ".ppm" || ext == ".webp";
}

std::vector<std::string> ListImageSequence(const std::string& spec) {
  std::vector<std::string> files;
  if (spec.find('%') != std::string::npos) {
    // printf pattern with one integer field (%d, %5d, %05d): frames from 0 (or 1) upwards until
    // the first missing number.
    static const std::regex kOneIntField(R"([^%]*%0?[0-9]*d[^%]*)");
    if (!std::regex_match(spec, kOneIntField)) return {};
    for (int start : {0, 1}) {
      for (int i = start;; ++i) {
        std::vector<char> buf(spec.size() + 32);
        std::snprintf(buf.data(), buf.size(), spec.c_str(), i);
        const std::string name(buf.data());
        if (!fs::is_regular_file(name)) break;
        files.push_back(name);
      }
      if (!files.empty()) break;
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
  if (StartsWith(spec, "camera:")) return std::make_unique<CaptureSource>(spec, options.fps);
  // A file that exists is a video even when its name has '%', '*' or '?' (100%.avi, a*b.avi).
  if (fs::is_regular_file(spec)) return std::make_unique<CaptureSource>(spec, options.fps);
  const bool sequence = spec.find('%') != std::string::npos ||
                        spec.find('*') != std::string::npos ||
                        spec.find('?') != std::string::npos || fs::is_directory(spec);
  if (sequence) {
    std::vector<std::string> files = ListImageSequence(spec);
    FV_REQUIRE(!files.empty(), "image sequence '{}' matches no image file", spec);
    return std::make_unique<ImageSequenceSource>(spec, std::move(files), options.fps);
  }
  return std::make_unique<CaptureSource>(spec, options.fps);
}

void VideoSource::CheckMatchesCamera(const Camera& camera, const std::string& camera_name) const {
  FV_REQUIRE(camera.width == width_ && camera.height == height_,
             "video '{}' is {}x{} but camera file '{}' is for {}x{} images", spec_, width_, height_,
             camera_name, camera.width, camera.height);
}

}  // namespace fv
