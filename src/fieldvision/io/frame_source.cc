#include "fieldvision/io/frame_source.h"

#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>

#include <fmt/format.h>

#include "fieldvision/camera/frame_size.h"
#include "fieldvision/io/source_backends.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/strings.h"

namespace fv::io {

const char* ToString(TimeOrigin origin) {
  switch (origin) {
    case TimeOrigin::kFrameRate:
      return "frame-rate";
    case TimeOrigin::kContainer:
      return "container";
    case TimeOrigin::kCsv:
      return "csv";
    case TimeOrigin::kDevice:
      return "device";
    case TimeOrigin::kPlayback:
      return "playback";
    case TimeOrigin::kArrival:
      return "arrival";
  }
  return "unknown";
}

void FrameSourceOptions::Check() const {
  FV_REQUIRE(std::isfinite(fps) && fps >= 0, "FrameSourceOptions.fps must be >= 0 (got {})", fps);
  FV_REQUIRE(time != TimeSource::kCsv || !timestamps_csv.empty(),
             "FrameSourceOptions.timestamps_csv is needed for CSV timestamps");
  FV_REQUIRE(std::isfinite(start_at_s) && start_at_s >= 0,
             "FrameSourceOptions.start_at_s must be >= 0 (got {})", start_at_s);
  FV_REQUIRE(live_buffer_frames >= 1 && live_buffer_frames <= 100000,
             "FrameSourceOptions.live_buffer_frames must be in [1, 100000] (got {})",
             live_buffer_frames);
  FV_REQUIRE(width >= 0 && height >= 0, "FrameSourceOptions.width/height must be >= 0");
  FV_REQUIRE(std::isfinite(exposure_us) && exposure_us >= 0,
             "FrameSourceOptions.exposure_us must be >= 0 (got {})", exposure_us);
}

std::map<long long, double> ReadTimestampsCsv(const std::string& path) {
  const util::CsvTable t = util::CsvTable::Read(path);
  t.Require({"frame", "time_s"});
  FV_REQUIRE(t.rows() > 0, "timestamps '{}' have a header but no rows", path);
  std::map<long long, std::pair<double, size_t>> rows;  // frame -> time, row
  for (size_t r = 0; r < t.rows(); ++r) {
    const long long f = t.GetInt(r, "frame");
    const double ts = t.GetDouble(r, "time_s");
    FV_REQUIRE(f >= 0, "{}: frame {} is negative (frames count from 0)", t.Where(r), f);
    FV_REQUIRE(std::isfinite(ts) && ts >= 0 && ts <= kMaxTimestampS,
               "{}: time_s {} is not in [0, {:g}] s", t.Where(r), ts, kMaxTimestampS);
    FV_REQUIRE(rows.emplace(f, std::make_pair(ts, r)).second, "{}: frame {} listed twice",
               t.Where(r), f);
  }
  std::map<long long, double> times;
  const std::pair<const long long, std::pair<double, size_t>>* previous = nullptr;
  for (const auto& row : rows) {
    if (previous != nullptr) {
      FV_REQUIRE(row.second.first > previous->second.first,
                 "{}: time_s {} of frame {} is not after {} of frame {} (times must increase with "
                 "the frame)",
                 t.Where(row.second.second), row.second.first, row.first, previous->second.first,
                 previous->first);
    }
    times.emplace_hint(times.end(), row.first, row.second.first);
    previous = &row;
  }
  // A camera's frames come more than once a second: a median step of a second or more is
  // milliseconds (or frame numbers) in time_s.
  std::vector<double> steps_s;
  for (auto it = times.begin(); std::next(it) != times.end(); ++it) {
    steps_s.push_back((std::next(it)->second - it->second) /
                      static_cast<double>(std::next(it)->first - it->first));
  }
  if (!steps_s.empty()) {
    const double step_s = util::Median(steps_s);
    FV_REQUIRE(step_s < 1.0,
               "timestamps '{}': frames are {:.4g} s apart (the median): is time_s in seconds "
               "(not milliseconds)?",
               path, step_s);
  }
  return times;
}

bool FrameSource::SkipFrame() {
  SourceFrame f;
  return ReadFrame(&f);
}

bool FrameSource::SeekFrame(long long /*frame*/) { return false; }

bool FrameSource::Read(cv::Mat* bgr, long long* frame, double* time_s) {
  SourceFrame f;
  if (!ReadFrame(&f)) return false;
  if (!f.jpeg.empty()) {
    decoder_.Decode(f.jpeg.data(), f.jpeg.size(), cv::Rect(), bgr,
                    fmt::format("video '{}' frame {}", name(), f.frame));
  } else {
    *bgr = f.bgr;
  }
  *frame = f.frame;
  *time_s = f.time_s;
  return true;
}

std::string FitCameraToSource(const FrameSource& source, camera::Camera& camera,
                              const std::string& camera_file) {
  const cv::Size size = source.FrameSize();
  return camera::FitCameraToFrames(camera, fmt::format("camera file '{}'", camera_file), size.width,
                                   size.height, fmt::format("video '{}'", source.name()));
}

double SystemClockNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::vector<std::string> FrameSourceBackends() {
  std::vector<std::string> out = {"file", "v4l2"};
  if (backend::HaveGStreamer()) out.push_back("gstreamer");
  if (backend::HaveAravis()) out.push_back("aravis");
  out.push_back("synth");
  return out;
}

namespace backend {

double SystemFromMonotonic(double monotonic_s) {
  timespec mono{};
  clock_gettime(CLOCK_MONOTONIC, &mono);
  const double now_mono = mono.tv_sec + 1e-9 * mono.tv_nsec;
  return SystemClockNow() - (now_mono - monotonic_s);
}

}  // namespace backend

std::unique_ptr<FrameSource> OpenFrameSource(const std::string& spec,
                                             const FrameSourceOptions& options) {
  options.Check();
  FV_REQUIRE(!spec.empty(), "empty video name");
  if (util::StartsWith(spec, "v4l2:") || util::StartsWith(spec, "camera:")) {
    return backend::OpenV4l2(spec, options);
  }
  if (util::StartsWith(spec, "gst:") || util::StartsWith(spec, "rtsp://") ||
      util::StartsWith(spec, "rtsps://")) {
    return backend::OpenGStreamer(spec, options);
  }
  if (util::StartsWith(spec, "aravis:")) return backend::OpenAravis(spec, options);
  if (util::StartsWith(spec, "synth:")) return backend::OpenSynth(spec, options);
  // Anything else with a scheme is a mistake, not a file name.
  const size_t colon = spec.find("://");
  if (colon != std::string::npos) {
    Throw(
        "video '{}': unknown source scheme '{}' (known: a file, an image pattern, v4l2:, "
        "camera:, gst:, rtsp://, aravis:, synth:)",
        spec, spec.substr(0, colon));
  }
  // An image sequence: one image file, a glob, a folder or a printf pattern whose files are
  // numbered from one of 0..1000 (a file that exists is a file, whatever its name). Other printf
  // patterns: OpenCV's reader. One image is decoded as a folder's are (libjpeg for a JPEG), not
  // by FFmpeg, whose chroma upsampling gives other pixels.
  const bool list =
      std::filesystem::is_regular_file(spec)
          ? !ListImageSequence(spec).empty()  // an image file is a sequence of one
          : spec.find_first_of("*?") != std::string::npos || std::filesystem::is_directory(spec) ||
                (spec.find('%') != std::string::npos && !ListImageSequence(spec).empty());
  std::unique_ptr<FrameSource> file =
      list ? backend::OpenImageList(spec, options) : backend::OpenFile(spec, options);
  if (options.realtime) return backend::Paced(std::move(file), options);
  return file;
}

}  // namespace fv::io
