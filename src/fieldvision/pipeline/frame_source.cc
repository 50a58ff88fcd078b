#include "fieldvision/pipeline/frame_source.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"

namespace fv {
namespace {

// The file of frame `index` of a printf pattern with one integer field (dir/%05d.jpg), or ""
// when the pattern has another form.
std::string PatternFile(const std::string& pattern, long long index) {
  static const std::regex kOneIntField(R"(^([^%]*)%(0?)([0-9]{0,3})d([^%]*)$)");
  std::smatch m;
  if (!std::regex_match(pattern, m, kOneIntField)) return "";
  const size_t width = m[3].length() > 0 ? std::stoul(m[3].str()) : 0;
  std::string number = std::to_string(index);
  if (number.size() < width) number.insert(0, width - number.size(), m[2].length() ? '0' : ' ');
  return m[1].str() + number + m[4].str();
}

bool HasJpegExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext == ".jpg" || ext == ".jpeg";
}

}  // namespace

void FrameSourceOptions::Check() const {
  FV_REQUIRE(std::isfinite(fps) && fps >= 0, "FrameSourceOptions.fps must be >= 0 (got {})", fps);
  FV_REQUIRE(time != TimeSource::kCsv || !timestamps_csv.empty(),
             "FrameSourceOptions.timestamps_csv is needed for CSV timestamps");
}

VideoFrameSource::VideoFrameSource(const std::string& path, const FrameSourceOptions& options)
    : path_(path), options_(options) {
  options.Check();
  const bool pattern = path.find('%') != std::string::npos;
  FV_REQUIRE(pattern || std::filesystem::exists(path), "video '{}' does not exist", path);
  bool opened = false;
  try {
    opened = capture_.open(path, cv::CAP_ANY);
  } catch (const cv::Exception&) {
    opened = false;
  }
  FV_REQUIRE(opened && capture_.isOpened(), "cannot open video '{}' (not a video OpenCV reads?)",
             path);
  const double container_fps = capture_.get(cv::CAP_PROP_FPS);
  fps_ = options.fps > 0 ? options.fps
                         : (std::isfinite(container_fps) && container_fps > 0 ? container_fps : 30);
  const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
  if (std::isfinite(count) && count > 0) frame_count_ = static_cast<long long>(count);
  if (options.time == TimeSource::kCsv) {
    const CsvTable t = CsvTable::Read(options.timestamps_csv);
    t.Require({"frame", "time_s"});
    for (size_t r = 0; r < t.rows(); ++r) {
      const long long f = t.GetInt(r, "frame");
      const double ts = t.GetDouble(r, "time_s");
      FV_REQUIRE(std::isfinite(ts), "{}: time_s is not finite", t.Where(r));
      FV_REQUIRE(times_.emplace(f, ts).second, "{}: frame {} listed twice", t.Where(r), f);
    }
  }
  // Motion JPEG through FFmpeg: the packets themselves are the JPEG frames.
  const int fourcc = static_cast<int>(capture_.get(cv::CAP_PROP_FOURCC));
  if (options.encoded && !pattern && fourcc == cv::VideoWriter::fourcc('M', 'J', 'P', 'G') &&
      capture_.getBackendName() == "FFMPEG") {
    encoded_ = capture_.set(cv::CAP_PROP_FORMAT, -1);
  }
  // A pattern of JPEG files: the files themselves are the frames (OpenCV's image reader starts
  // at the first of indices 0..1000 that exists; so does this).
  if (options.encoded && pattern && HasJpegExtension(path) && !PatternFile(path, 0).empty()) {
    for (long long i = 0; i <= 1000; ++i) {
      if (std::filesystem::exists(PatternFile(path, i))) {
        first_file_ = i;
        break;
      }
    }
    if (first_file_ >= 0) {
      encoded_ = true;
      jpeg_files_ = true;
      long long n = 0;
      while (std::filesystem::exists(PatternFile(path, first_file_ + n))) ++n;
      frame_count_ = n;
      capture_.release();
    }
  }
  if (encoded_) {
    has_pending_ = GrabFrame(&pending_frame_);
    FV_REQUIRE(has_pending_, "video '{}' has no readable frame", path);
    size_ = JpegRegionDecoder::ReadSize(pending_frame_.jpeg.data(), pending_frame_.jpeg.size(),
                                        fmt::format("video '{}' frame 0", path));
    return;
  }
  has_pending_ = Grab(&pending_, &pending_time_s_);
  FV_REQUIRE(has_pending_, "video '{}' has no readable frame", path);
  size_ = pending_.size();
}

bool VideoFrameSource::GrabFrame(SourceFrame* out) {
  if (jpeg_files_) {
    const std::string file = PatternFile(path_, first_file_ + next_frame_);
    std::ifstream in(file, std::ios::binary);
    if (!in) return false;  // the end of the sequence
    out->jpeg.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    FV_REQUIRE(!in.bad(), "cannot read '{}'", file);
    out->bgr = cv::Mat();
    out->time_s = TimeOf(next_frame_);
    return true;
  }
  cv::Mat packet;
  bool ok = false;
  try {
    ok = capture_.read(packet);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok || packet.empty()) return false;
  const auto* p = packet.ptr<uint8_t>();
  out->jpeg.assign(p, p + packet.total() * packet.elemSize());
  out->bgr = cv::Mat();
  out->time_s = TimeOf(next_frame_);
  return true;
}

bool VideoFrameSource::ReadFrame(SourceFrame* out) {
  if (!encoded_) {
    out->jpeg.clear();
    return Read(&out->bgr, &out->frame, &out->time_s);
  }
  if (has_pending_) {
    std::swap(*out, pending_frame_);
    has_pending_ = false;
  } else if (!GrabFrame(out)) {
    return false;
  }
  out->frame = next_frame_++;
  return true;
}

double VideoFrameSource::TimeOf(long long f) {
  switch (options_.time) {
    case TimeSource::kFrameRate:
      return f / fps_;
    case TimeSource::kContainer: {
      if (jpeg_files_) return f / fps_;  // image files carry no capture times
      const double ms = capture_.get(cv::CAP_PROP_POS_MSEC);
      return std::isfinite(ms) ? ms / 1000.0 : f / fps_;
    }
    case TimeSource::kCsv: {
      const auto it = times_.find(f);
      FV_REQUIRE(it != times_.end(), "timestamps '{}' have no row for frame {} of video '{}'",
                 options_.timestamps_csv, f, path_);
      return it->second;
    }
  }
  return f / fps_;
}

bool VideoFrameSource::Grab(cv::Mat* bgr, double* time_s) {
  bool ok = false;
  try {
    ok = capture_.read(*bgr);
  } catch (const cv::Exception&) {
    ok = false;  // a corrupt frame ends the stream; the pipeline reports where
  }
  if (!ok || bgr->empty()) return false;
  if (bgr->channels() == 1) cv::cvtColor(*bgr, *bgr, cv::COLOR_GRAY2BGR);
  *time_s = TimeOf(next_frame_);
  return true;
}

bool VideoFrameSource::Read(cv::Mat* bgr, long long* frame, double* time_s) {
  if (encoded_) {
    SourceFrame f;
    if (!ReadFrame(&f)) return false;
    decoder_.Decode(f.jpeg.data(), f.jpeg.size(), cv::Rect(), bgr,
                    fmt::format("video '{}' frame {}", path_, f.frame));
    *frame = f.frame;
    *time_s = f.time_s;
    return true;
  }
  if (has_pending_) {
    *bgr = pending_;
    *time_s = pending_time_s_;
    pending_ = cv::Mat();
    has_pending_ = false;
  } else if (!Grab(bgr, time_s)) {
    return false;
  }
  *frame = next_frame_++;
  return true;
}

}  // namespace fv
