#include "fieldvision/pipeline/camera_stage.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "fieldvision/util/error.h"

namespace fv::pipeline {

void BallTrackOptions::Check() const {
  FV_REQUIRE(full_scan_every >= 1, "BallTrackOptions.full_scan_every must be >= 1 (got {})",
             full_scan_every);
  FV_REQUIRE(std::isfinite(window_radii) && window_radii >= 2,
             "BallTrackOptions.window_radii must be >= 2 (got {})", window_radii);
  FV_REQUIRE(min_window_px >= 8, "BallTrackOptions.min_window_px must be >= 8 (got {})",
             min_window_px);
}

bool HasAccepted(const std::vector<recon::BallObservation>& obs) {
  return std::any_of(obs.begin(), obs.end(),
                     [](const recon::BallObservation& o) { return !o.weak; });
}

// Where a camera stage looks next: the window around the ball's predicted image position.
class CameraStage::Track {
 public:
  explicit Track(const BallTrackOptions& o) : o_(o) {}
  // The window for the next frame, or an empty rectangle for the whole frame.
  cv::Rect Window(const cv::Size& image) const {
    if (!o_.enabled || !active_ || since_full_ + 1 >= o_.full_scan_every) return {};
    const Eigen::Vector2d p = centre_ + velocity_;
    const double half =
        std::max<double>(o_.min_window_px, o_.window_radii * radius_ + velocity_.norm());
    const int x0 = static_cast<int>(std::floor(p.x() - half));
    const int y0 = static_cast<int>(std::floor(p.y() - half));
    const int x1 = static_cast<int>(std::ceil(p.x() + half));
    const int y1 = static_cast<int>(std::ceil(p.y() + half));
    const cv::Rect r = cv::Rect(x0, y0, x1 - x0, y1 - y0) & cv::Rect(cv::Point(0, 0), image);
    return r.area() > 0 ? r : cv::Rect();
  }
  // Whether the window's best accepted candidate is where the ball was expected (within two of its
  // radii): if not, the track may have been taken by another object and the frame is searched
  // whole.
  bool Confirms(const std::vector<recon::BallObservation>& obs) const {
    const recon::BallObservation* best = Best(obs);
    return best != nullptr &&
           (best->centre_px - (centre_ + velocity_)).norm() <= 2.0 * radius_ + 2.0;
  }
  void Update(const std::vector<recon::BallObservation>& obs, bool full) {
    since_full_ = full ? 0 : since_full_ + 1;
    const recon::BallObservation* best = Best(obs);
    if (best == nullptr) {
      active_ = false;
      return;
    }
    velocity_ = active_ ? Eigen::Vector2d(best->centre_px - centre_) : Eigen::Vector2d::Zero();
    centre_ = best->centre_px;
    radius_ = std::max(best->radius_px, 2.0);
    active_ = true;
  }

 private:
  static const recon::BallObservation* Best(const std::vector<recon::BallObservation>& obs) {
    const recon::BallObservation* best = nullptr;
    for (const recon::BallObservation& b : obs) {
      if (!b.weak && (best == nullptr || b.score > best->score)) best = &b;
    }
    return best;
  }
  BallTrackOptions o_;
  bool active_ = false;
  int since_full_ = 0;
  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity_ = Eigen::Vector2d::Zero();
  double radius_ = 0.0;
};

CameraStage::CameraStage(int camera_index, const camera::Camera& camera,
                         BallRegionDetectFn detector, const BallTrackOptions& track,
                         std::string source_name)
    : camera_index_(camera_index),
      size_(camera.width, camera.height),
      detector_(std::move(detector)),
      source_name_(std::move(source_name)),
      track_(std::make_unique<Track>(track)) {
  track.Check();
  FV_REQUIRE(detector_ != nullptr, "camera stage {}: no detector", camera_index);
}

CameraStage::~CameraStage() = default;
CameraStage::CameraStage(CameraStage&&) noexcept = default;

void CameraStage::CheckSize(const cv::Size& got, long long frame) const {
  FV_REQUIRE(got == size_, "video '{}' frame {} is {}x{}, camera {} is {}x{}", source_name_, frame,
             got.width, got.height, camera_index_, size_.width, size_.height);
}

// The frame's pixels in `roi` (empty: all); null for a damaged encoded frame, which is counted.
const cv::Mat* CameraStage::Image(const io::SourceFrame& in, const cv::Rect& roi) {
  if (in.jpeg.empty()) return &in.bgr;
  const std::string what = fmt::format("video '{}' frame {}", source_name_, in.frame);
  try {
    decoder_.Decode(in.jpeg.data(), in.jpeg.size(), roi, &decoded_, what);
  } catch (const Error& e) {
    // A readable header of another size is the wrong video, not a damaged frame.
    cv::Size got = size_;
    try {
      got = io::JpegRegionDecoder::ReadSize(in.jpeg.data(), in.jpeg.size(), what);
    } catch (const Error&) {
    }
    CheckSize(got, in.frame);
    if (stats_.bad_frames++ == 0) stats_.first_bad_frame = e.what();
    return nullptr;
  }
  return &decoded_;
}

CameraMessage CameraStage::Process(const io::SourceFrame& in) {
  CameraMessage m;
  m.camera = camera_index_;
  m.frame = in.frame;
  m.time_s = in.time_s;
  const cv::Rect window = track_->Window(size_);
  bool full = window.empty();
  const cv::Mat* frame = Image(in, window);
  if (frame != nullptr) {
    CheckSize(frame->size(), in.frame);
    if (!full) {
      m.candidates = detector_(*frame, window);
      ++stats_.window_scans;
      full = !track_->Confirms(m.candidates);
    }
    if (full && !window.empty()) frame = Image(in, cv::Rect());
    if (frame == nullptr) {
      m.candidates.clear();
    } else if (full) {
      m.candidates = detector_(*frame, cv::Rect());
      ++stats_.full_scans;
    }
  }
  full = full || frame == nullptr;
  track_->Update(m.candidates, full);
  ++stats_.frames;
  for (const recon::BallObservation& o : m.candidates) stats_.candidates += !o.weak;
  return m;
}

}  // namespace fv::pipeline
