#include "fieldvision/pipeline/frame_source.h"

#include <cmath>
#include <filesystem>

#include <opencv2/imgproc.hpp>

#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"

namespace fv {

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
  has_pending_ = Grab(&pending_, &pending_time_s_);
  FV_REQUIRE(has_pending_, "video '{}' has no readable frame", path);
  size_ = pending_.size();
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
  const long long f = next_frame_;
  switch (options_.time) {
    case TimeSource::kFrameRate:
      *time_s = f / fps_;
      break;
    case TimeSource::kContainer: {
      const double ms = capture_.get(cv::CAP_PROP_POS_MSEC);
      *time_s = std::isfinite(ms) ? ms / 1000.0 : f / fps_;
      break;
    }
    case TimeSource::kCsv: {
      const auto it = times_.find(f);
      FV_REQUIRE(it != times_.end(), "timestamps '{}' have no row for frame {} of video '{}'",
                 options_.timestamps_csv, f, path_);
      *time_s = it->second;
      break;
    }
  }
  return true;
}

bool VideoFrameSource::Read(cv::Mat* bgr, long long* frame, double* time_s) {
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
