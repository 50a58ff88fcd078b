// Frame-source backend: an image sequence given as a glob (dir/*.png) or a folder of images, in
// name order (ListImageSequence, video_source.h); times from the frame rate (options.fps, else the
// `fps` of a synth scene.json in the images' folder or the one above it) or a frame,time_s CSV;
// without any, no rate is known (rate_known(): fps() is a stand-in 30). JPEG files are delivered
// encoded on request (the files' bytes).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "fieldvision/io/image_file.h"
#include "fieldvision/io/jpeg_orientation.h"
#include "fieldvision/io/source_backends.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/strings.h"

namespace fv::io::backend {
namespace {

// The frame rate a scene.json (synth's scene file) beside the images or one folder up declares;
// nullopt without one (or one that cannot be read: the caller then asks for --fps).
std::optional<double> SceneFileRate(const std::string& first_image) {
  const std::filesystem::path dir = std::filesystem::path(first_image).parent_path();
  for (const std::filesystem::path& d : {dir, dir.parent_path()}) {
    const std::filesystem::path scene = d / "scene.json";
    if (!std::filesystem::is_regular_file(scene)) continue;
    try {
      const nlohmann::json j = util::ReadJsonFile(scene.string(), "scene");
      const auto it = j.find("fps");
      if (it == j.end() || !it->is_number()) return std::nullopt;
      const double fps = it->get<double>();
      if (std::isfinite(fps) && fps > 0 && fps <= 100000) return fps;
    } catch (const Error&) {
    }
    return std::nullopt;
  }
  return std::nullopt;
}

bool IsJpeg(const std::string& path) {
  const std::string ext = util::ToLower(std::filesystem::path(path).extension().string());
  return ext == ".jpg" || ext == ".jpeg";
}

class ImageListSource : public FrameSource {
 public:
  ImageListSource(const std::string& spec, std::vector<std::string> files,
                  const FrameSourceOptions& o)
      : spec_(spec),
        files_(std::move(files)),
        fps_(o.fps > 0 ? o.fps : 30.0),
        rate_known_(o.fps > 0 || o.time == TimeSource::kCsv) {
    encoded_ = o.encoded;
    for (const std::string& f : files_) encoded_ = encoded_ && IsJpeg(f);
    if (o.time == TimeSource::kCsv) {
      times_ = ReadTimestampsCsv(o.timestamps_csv);
      origin_ = TimeOrigin::kCsv;
      csv_ = o.timestamps_csv;
    }
    const cv::Mat first = TryReadImage(files_.front());
    FV_REQUIRE(!first.empty() || files_.front() != spec,
               "image '{}' cannot be read (damaged or not an image)", spec);
    FV_REQUIRE(!first.empty(), "image sequence '{}': cannot read its first image '{}'", spec,
               files_.front());
    size_ = first.size();
    if (!rate_known_) {
      if (const std::optional<double> fps = SceneFileRate(files_.front())) {
        fps_ = *fps;
        rate_known_ = true;
      }
    }
  }
  bool ReadFrame(SourceFrame* out) override {
    if (next_ >= static_cast<long long>(files_.size())) return false;
    const std::string& file = files_[next_];
    out->bgr = cv::Mat();
    out->jpeg.clear();
    if (encoded_) {
      std::ifstream in(file, std::ios::binary);
      out->jpeg.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      FV_REQUIRE(in.good() || in.eof(), "image sequence '{}': frame {} ('{}') cannot be read",
                 spec_, next_, file);
      FV_REQUIRE(!out->jpeg.empty(), "image sequence '{}': frame {} ('{}') is empty", spec_, next_,
                 file);
      // A still to be turned (EXIF orientation) is delivered decoded, turned as cv::imread does.
      if (JpegOrientation(out->jpeg.data(), out->jpeg.size()) != 1) out->jpeg.clear();
    }
    if (out->jpeg.empty()) {
      out->bgr = TryReadImage(file);
      FV_REQUIRE(!out->bgr.empty(), "image sequence '{}': frame {} ('{}') cannot be read", spec_,
                 next_, file);
      FV_REQUIRE(out->bgr.size() == size_,
                 "image sequence '{}': frame {} ('{}') is {}x{}, the first frame {}x{}", spec_,
                 next_, file, out->bgr.cols, out->bgr.rows, size_.width, size_.height);
    }
    out->frame = next_;
    out->origin = origin_;
    if (origin_ == TimeOrigin::kCsv) {
      const auto it = times_.find(next_);
      FV_REQUIRE(it != times_.end(), "timestamps '{}' have no row for frame {} of '{}'", csv_,
                 next_, spec_);
      out->time_s = it->second;
    } else {
      out->time_s = next_ / fps_;
    }
    ++next_;
    return true;
  }
  bool SkipFrame() override {
    if (next_ >= static_cast<long long>(files_.size())) return false;
    ++next_;
    return true;
  }
  bool SeekFrame(long long frame) override {
    if (frame < next_ || frame >= static_cast<long long>(files_.size())) return false;
    next_ = frame;
    return true;
  }
  long long FrameCount() const override { return static_cast<long long>(files_.size()); }
  cv::Size FrameSize() const override { return size_; }
  std::string name() const override { return spec_; }
  double fps() const override { return fps_; }
  bool encoded() const override { return encoded_; }
  bool rate_known() const override { return rate_known_; }
  bool SkipsWithoutDecoding() const override { return true; }

 private:
  std::string spec_;
  std::vector<std::string> files_;
  double fps_;
  bool rate_known_ = false;
  bool encoded_ = false;
  TimeOrigin origin_ = TimeOrigin::kFrameRate;
  std::map<long long, double> times_;
  std::string csv_;
  cv::Size size_;
  long long next_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> OpenImageList(const std::string& spec,
                                           const FrameSourceOptions& options) {
  std::vector<std::string> files = ListImageSequence(spec);
  FV_REQUIRE(!files.empty(), "image sequence '{}' matches no image file", spec);
  return std::make_unique<ImageListSource>(spec, std::move(files), options);
}

}  // namespace fv::io::backend
