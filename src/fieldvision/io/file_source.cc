// Frame-source backend: video files OpenCV reads and the printf image patterns that are no image
// sequence of existing files (image_list_source.cc reads those), with times from the frame rate,
// the container or a frame,time_s CSV. Motion-JPEG frames (an AVI's read directly, another
// container's packets through FFmpeg) can be delivered encoded (the ball pipeline's
// window-decoding path); an AVI's are decoded by libjpeg-turbo either way, so every command sees
// the same pixels.
#include <cmath>
#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/codecs/codecs.h"
#include "fieldvision/io/avi_mjpeg.h"
#include "fieldvision/io/live_source.h"
#include "fieldvision/io/source_backends.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::io::backend {
namespace {

std::string LowerExtension(const std::string& path) {
  return util::ToLower(std::filesystem::path(path).extension().string());
}

class FileSource : public FrameSource {
 public:
  FileSource(const std::string& path, const FrameSourceOptions& options);
  bool ReadFrame(SourceFrame* out) override;
  bool SkipFrame() override;
  bool SeekFrame(long long frame) override;
  bool SkipsWithoutDecoding() const override { return avi_ != nullptr || encoded_; }
  bool encoded() const override { return encoded_; }
  long long FrameCount() const override { return frame_count_; }
  cv::Size FrameSize() const override { return size_; }
  std::string name() const override { return path_; }
  double fps() const override { return fps_; }
  bool rate_known() const override { return rate_known_; }
  std::string FramesNote() const override { return chroma_.Note(); }

 private:
  bool Grab(SourceFrame* out);         // decoded
  bool GrabEncoded(SourceFrame* out);  // encoded
  double TimeOf(long long frame);
  std::string path_;
  FrameSourceOptions options_;
  TimeOrigin origin_ = TimeOrigin::kFrameRate;
  std::unique_ptr<AviMjpegReader> avi_;  // a Motion-JPEG AVI read directly
  JpegRegionDecoder decoder_;            // decoded: its frames (the encoded path's pixels)
  std::vector<uint8_t> packet_;
  std::unique_ptr<cv::VideoCapture> capture_;  // else OpenCV's
  RepeatedChromaRepair chroma_;                // its frames' chroma (repeated_chroma.h)
  std::map<long long, double> times_;          // kCsv
  bool encoded_ = false;
  SourceFrame pending_;  // the first frame, read when opening
  bool has_pending_ = false;
  long long next_frame_ = 0;
  long long frame_count_ = -1;
  double fps_ = 30.0;
  bool rate_known_ = true;
  cv::Size size_;
};

FileSource::FileSource(const std::string& path, const FrameSourceOptions& options)
    : path_(path), options_(options) {
  // A file that exists is a video even when its name has a '%' (100%.avi).
  const bool pattern =
      path.find('%') != std::string::npos && !std::filesystem::is_regular_file(path);
  FV_REQUIRE(pattern || std::filesystem::exists(path), "video '{}' does not exist", path);
  FV_REQUIRE(pattern || !std::filesystem::is_directory(path),
             "video '{}' is a folder (give an image pattern such as '{}/%05d.jpg')", path, path);
  if (!pattern) avi_ = AviMjpegReader::Open(path);
  if (!avi_) {
    capture_ = codecs::NewVideoCapture();
    FV_REQUIRE(OpenVideoFile(*capture_, path), "cannot open video '{}' (not a video OpenCV reads?)",
               path);
    codecs::DecoderProblems();  // count what FFmpeg's decoders conceal (main warns)
  }
  const double container_fps = avi_ ? avi_->fps() : capture_->get(cv::CAP_PROP_FPS);
  // A rate above any camera's (--fps allows 100000) is a damaged header's: no rate of its own.
  const bool container_rate =
      !pattern && std::isfinite(container_fps) && container_fps > 0 && container_fps <= 1e5;
  fps_ = options.fps > 0 ? options.fps : (container_rate ? container_fps : 30);
  rate_known_ = options.fps > 0 || options.time == TimeSource::kCsv || container_rate;
  const double count =
      avi_ ? static_cast<double>(avi_->frame_count()) : capture_->get(cv::CAP_PROP_FRAME_COUNT);
  if (std::isfinite(count) && count > 0) frame_count_ = static_cast<long long>(count);
  origin_ = options.time == TimeSource::kCsv         ? TimeOrigin::kCsv
            : options.time == TimeSource::kContainer ? TimeOrigin::kContainer
                                                     : TimeOrigin::kFrameRate;
  if (options.time == TimeSource::kCsv) {
    times_ = ReadTimestampsCsv(options.timestamps_csv);
  }
  // Motion JPEG through FFmpeg: the packets themselves are the JPEG frames. Raw packets carry
  // no container times (CAP_PROP_POS_MSEC stays 0), so with container times asked for only an
  // AVI's (a fixed rate: frame / fps) are read raw; another container is decoded by FFmpeg.
  if (avi_) {
    encoded_ = options.encoded;
  } else if (options.encoded && !pattern) {
    const int fourcc = static_cast<int>(capture_->get(cv::CAP_PROP_FOURCC));
    const bool rate_times =
        options.time != TimeSource::kContainer || LowerExtension(path) == ".avi";
    if (fourcc == codecs::FourCc('M', 'J', 'P', 'G') &&
        codecs::BackendName(*capture_) == "FFMPEG" && rate_times) {
      encoded_ = capture_->set(cv::CAP_PROP_FORMAT, -1);
    }
  }
  has_pending_ = encoded_ ? GrabEncoded(&pending_) : Grab(&pending_);
  FV_REQUIRE(has_pending_, "video '{}' has no readable frame", path);
  size_ = encoded_ ? JpegRegionDecoder::ReadSize(pending_.jpeg.data(), pending_.jpeg.size(),
                                                 fmt::format("video '{}' frame 0", path))
                   : pending_.bgr.size();
}

bool FileSource::GrabEncoded(SourceFrame* out) {
  out->bgr = cv::Mat();
  if (avi_) {
    if (!avi_->Next(&out->jpeg)) return false;
  } else {
    cv::Mat packet;
    bool ok = false;
    try {
      ok = capture_->read(packet);
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (!ok || packet.empty()) return false;
    const auto* p = packet.ptr<uint8_t>();
    out->jpeg.assign(p, p + packet.total() * packet.elemSize());
  }
  out->time_s = TimeOf(next_frame_);
  return true;
}

bool FileSource::Grab(SourceFrame* out) {
  out->jpeg.clear();
  bool ok = false;
  if (avi_) {
    // libjpeg-turbo, as the encoded path and the camera stages decode: the same pixels whether
    // a frame is read decoded or encoded.
    try {
      ok = avi_->Next(&packet_) &&
           !decoder_.Decode(packet_.data(), packet_.size(), cv::Rect(), &out->bgr, path_).empty();
    } catch (const Error&) {
      ok = false;  // a corrupt frame ends the stream; the pipeline reports where
    }
  } else {
    try {
      ok = capture_->read(out->bgr);
    } catch (const cv::Exception&) {
      ok = false;  // a corrupt frame ends the stream; the pipeline reports where
    }
  }
  if (!ok || out->bgr.empty()) return false;
  if (out->bgr.channels() == 1) cv::cvtColor(out->bgr, out->bgr, cv::COLOR_GRAY2BGR);
  if (!avi_) chroma_.Apply(&out->bgr);
  out->time_s = TimeOf(next_frame_);
  return true;
}

bool FileSource::ReadFrame(SourceFrame* out) {
  if (has_pending_) {
    std::swap(*out, pending_);
    pending_ = SourceFrame();
    has_pending_ = false;
  } else if (!(encoded_ ? GrabEncoded(out) : Grab(out))) {
    CheckEndOfStream(path_, next_frame_, frame_count_);
    return false;
  }
  out->frame = next_frame_++;
  out->origin = origin_;
  return true;
}

bool FileSource::SkipFrame() {
  if (has_pending_) {
    pending_ = SourceFrame();
    has_pending_ = false;
  } else if (encoded_) {
    SourceFrame f;
    if (!GrabEncoded(&f)) {
      CheckEndOfStream(path_, next_frame_, frame_count_);
      return false;
    }
  } else {
    bool ok = false;
    try {
      ok = avi_ ? avi_->Next(&packet_) : capture_->grab();  // no decoding
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (!ok) {
      CheckEndOfStream(path_, next_frame_, frame_count_);
      return false;
    }
  }
  ++next_frame_;
  return true;
}

bool FileSource::SeekFrame(long long frame) {
  if (frame < next_frame_ || (frame_count_ > 0 && frame >= frame_count_)) return false;
  // Motion-JPEG packets skip without decoding; the next frame or two are as cheap to decode.
  constexpr long long kDecodeRather = 2;
  if (SkipsWithoutDecoding() || frame - next_frame_ <= kDecodeRather) {
    while (next_frame_ < frame) {
      if (!SkipFrame()) return false;
    }
    return true;
  }
  bool ok = false;
  try {
    ok = capture_->set(cv::CAP_PROP_POS_FRAMES, static_cast<double>(frame));
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) return false;
  pending_ = SourceFrame();
  has_pending_ = false;
  next_frame_ = frame;
  return true;
}

double FileSource::TimeOf(long long f) {
  switch (options_.time) {
    case TimeSource::kFrameRate:
      return f / fps_;
    case TimeSource::kContainer: {
      // Raw packets carry no capture times that OpenCV reports (an AVI read directly: a fixed
      // rate).
      if (encoded_ || avi_) return f / fps_;
      const double ms = capture_->get(cv::CAP_PROP_POS_MSEC);
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

}  // namespace

std::unique_ptr<FrameSource> OpenFile(const std::string& path, const FrameSourceOptions& options) {
  return std::make_unique<FileSource>(path, options);
}

}  // namespace fv::io::backend
