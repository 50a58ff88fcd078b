#include "fieldvision/pipeline/camera_stage.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::pipeline {

void BallTrackOptions::Check() const {
  FV_REQUIRE(full_scan_every >= 1, "BallTrackOptions.full_scan_every must be >= 1 (got {})",
             full_scan_every);
  FV_REQUIRE(scan_bands >= 1 && scan_bands <= full_scan_every,
             "BallTrackOptions.scan_bands must be 1..full_scan_every ({}) (got {})",
             full_scan_every, scan_bands);
  FV_REQUIRE(unconfirmed_scan_every >= 0,
             "BallTrackOptions.unconfirmed_scan_every must be >= 0 (got {})",
             unconfirmed_scan_every);
  FV_REQUIRE(std::isfinite(window_radii) && window_radii >= 2,
             "BallTrackOptions.window_radii must be >= 2 (got {})", window_radii);
  FV_REQUIRE(max_guided_frames >= 0, "BallTrackOptions.max_guided_frames must be >= 0 (got {})",
             max_guided_frames);
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
  // `phase`: the whole frame is searched in the frames n (from 0) where (n + phase) %
  // full_scan_every is 0, besides when the ball is lost; cameras with other phases do so in other
  // frames.
  Track(const BallTrackOptions& o, int phase) : o_(o), phase_(phase) {}
  // The window for the next frame, or an empty rectangle for the whole frame.
  cv::Rect Window(const cv::Size& image) const {
    if (!o_.enabled || !active_ || (o_.scan_bands == 1 && Slot() == 0)) return {};
    return ExpectedWindow(image);
  }
  // The window around the expected place, whatever the frame's slot.
  cv::Rect ExpectedWindow(const cv::Size& image) const {
    const Eigen::Vector2d p = ExpectedCentre();
    const double half =
        std::max<double>(o_.min_window_px, o_.window_radii * radius_ + velocity_.norm());
    const int x0 = static_cast<int>(std::floor(p.x() - half));
    const int y0 = static_cast<int>(std::floor(p.y() - half));
    const int x1 = static_cast<int>(std::ceil(p.x() + half));
    const int y1 = static_cast<int>(std::ceil(p.y() + half));
    const cv::Rect r = cv::Rect(x0, y0, x1 - x0, y1 - y0) & cv::Rect(cv::Point(0, 0), image);
    return r.area() > 0 ? r : cv::Rect();
  }
  // The band of rows to search besides the window in this frame (empty: none).
  cv::Rect Band(const cv::Size& image) const {
    if (!o_.enabled || !active_ || o_.scan_bands == 1 || Slot() >= o_.scan_bands) return {};
    const int core = (image.height + o_.scan_bands - 1) / o_.scan_bands;
    const int margin = static_cast<int>(std::ceil(1.5 * 4.0 * radius_ + 4.0));
    const int y0 = std::max(0, Slot() * core - margin);
    const int y1 = std::min(image.height, (Slot() + 1) * core + margin);
    return y1 > y0 ? cv::Rect(0, y0, image.width, y1 - y0) : cv::Rect();
  }
  // Whether the window's best accepted candidate is where the ball was expected (within two of its
  // radii): if not, the track may have been taken by another object and the frame is searched
  // whole.
  bool Confirms(const std::vector<recon::BallObservation>& obs) const {
    const recon::BallObservation* best = Best(obs);
    return best != nullptr && (best->centre_px - ExpectedCentre()).norm() <= 2.0 * radius_ + 2.0;
  }
  // Whether a guided fit may look for the ball at its expected place (Expected).
  bool MayGuide() const { return o_.enabled && active_ && guided_run_ < o_.max_guided_frames; }
  Eigen::Vector2d ExpectedCentre() const { return centre_ + velocity_; }
  // Where the fusion expects the ball: taken unless the track expects it there too.
  void Steer(const ExpectedBall& e) {
    if (!o_.enabled) return;
    if (active_ &&
        (ExpectedCentre() - e.centre_px).norm() <= 2.0 * std::max(radius_, e.radius_px) + 2.0) {
      return;
    }
    centre_ = e.centre_px - e.step_px;
    velocity_ = e.step_px;
    radius_ = std::max(e.radius_px, 2.0);
    active_ = true;
  }
  double radius() const { return radius_; }
  int unconfirmed_scan_every() const { return o_.unconfirmed_scan_every; }
  // `guided`: the candidate of obs that a guided fit gave, or null.
  void Update(const std::vector<recon::BallObservation>& obs,
              const recon::BallObservation* guided) {
    ++frames_;
    const recon::BallObservation* best = Best(obs);
    if (best == nullptr) {
      active_ = false;
      guided_run_ = 0;
      return;
    }
    guided_run_ = best == guided ? guided_run_ + 1 : 0;
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
  int Slot() const { return static_cast<int>((frames_ + phase_) % o_.full_scan_every); }
  int phase_;
  long long frames_ = 0;  // frames seen
  int guided_run_ = 0;    // frames in a row tracked by guided fits alone
  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity_ = Eigen::Vector2d::Zero();
  double radius_ = 0.0;
};

namespace {

// The camera's phase in the whole-frame searches, from its name (FNV-1a): the same camera gets the
// same phase in a node as in the in-process pipeline, so both give the same candidates.
int ScanPhase(const std::string& camera_name, int full_scan_every) {
  return static_cast<int>(util::Fnv1a64(camera_name) % static_cast<uint64_t>(full_scan_every));
}

// Adds the band's candidates to the window's, except those on a ball already there; accepted
// first, best first, and no more weak candidates than either list had.
void AddBandCandidates(std::vector<recon::BallObservation> band,
                       std::vector<recon::BallObservation>* candidates) {
  auto weak_count = [](const std::vector<recon::BallObservation>& v) {
    return std::count_if(v.begin(), v.end(),
                         [](const recon::BallObservation& o) { return o.weak; });
  };
  const auto max_weak = std::max(weak_count(band), weak_count(*candidates));
  const size_t from_window = candidates->size();
  for (recon::BallObservation& b : band) {
    const bool known =
        std::any_of(candidates->begin(), candidates->begin() + static_cast<long>(from_window),
                    [&](const recon::BallObservation& c) {
                      return (c.centre_px - b.centre_px).norm() < std::max(c.radius_px, 2.0);
                    });
    if (!known) candidates->push_back(std::move(b));
  }
  std::stable_sort(candidates->begin(), candidates->end(),
                   [](const recon::BallObservation& a, const recon::BallObservation& b) {
                     if (a.weak != b.weak) return !a.weak;
                     return a.score > b.score;
                   });
  long weak = 0;
  candidates->erase(
      std::remove_if(candidates->begin(), candidates->end(),
                     [&](const recon::BallObservation& o) { return o.weak && ++weak > max_weak; }),
      candidates->end());
}

}  // namespace

CameraStage::CameraStage(int camera_index, const camera::Camera& camera,
                         BallRegionDetectFn detector, const BallTrackOptions& track,
                         std::string source_name, BallGuidedFn guided)
    : camera_index_(camera_index),
      camera_(camera),
      size_(camera.width, camera.height),
      detector_(std::move(detector)),
      guided_(std::move(guided)),
      source_name_(std::move(source_name)),
      track_() {
  track.Check();
  track_ = std::make_unique<Track>(track, ScanPhase(camera.name, track.full_scan_every));
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

// While the window confirms the track: this frame's band of rows, if it has one.
void CameraStage::SearchBand(const io::SourceFrame& in,
                             std::vector<recon::BallObservation>* candidates) {
  const cv::Rect band = track_->Band(size_);
  if (band.empty()) return;
  const cv::Mat* frame = Image(in, band);
  if (frame == nullptr) return;
  AddBandCandidates(detector_(*frame, band), candidates);
  ++stats_.band_scans;
}

long CameraStage::AddGuided(const cv::Mat& frame, std::vector<recon::BallObservation>* candidates) {
  if (!guided_ || !track_->MayGuide() || track_->Confirms(*candidates)) return -1;
  std::optional<recon::BallObservation> found =
      guided_(frame, track_->ExpectedWindow(size_), track_->ExpectedCentre(), track_->radius());
  if (!found || found->weak) return -1;
  // After the accepted candidates, before the weak ones.
  const auto at = std::find_if(candidates->begin(), candidates->end(),
                               [](const recon::BallObservation& o) { return o.weak; });
  const long index = at - candidates->begin();
  candidates->insert(at, *found);
  ++stats_.guided;
  return index;
}

void CameraStage::FollowHint(const io::SourceFrame& in) {
  if (hints_ == nullptr) return;
  const std::optional<BallHint> hint = hints_->Get(camera_index_, stats_.frames);
  const double dt_s = stats_.frames > 0 ? in.time_s - last_time_s_ : 0.0;
  last_time_s_ = in.time_s;
  const bool recent = hint && in.time_s - hint->time_s <= hints_->options().max_age_s;
  unconfirmed_ = recent ? 0 : unconfirmed_ + 1;
  if (!hint) return;
  if (auto e = ExpectBall(*hint, camera_, in.time_s, dt_s, hints_->options())) track_->Steer(*e);
}

bool CameraStage::UnconfirmedScan(long long frame) {
  const int every = track_->unconfirmed_scan_every();
  // A camera node learns of a loss when its lost hints arrive, at another frame than the other
  // nodes: it searches whole at the first frame it processes of each block of `every` frame
  // numbers, so that the nodes search the same frames (a position needs two). In one process the
  // cameras lose their confirmation together and count alike.
  const long long block = every > 0 ? frame / every : 0;
  const bool block_start = block != last_block_;
  last_block_ = block;
  if (hints_ == nullptr || !(no_hint_means_unconfirmed_ || hints_->TellsLoss()) || every == 0 ||
      unconfirmed_ < every) {
    return false;
  }
  if (!no_hint_means_unconfirmed_ && !block_start) return false;
  unconfirmed_ = 0;
  return true;
}

CameraMessage CameraStage::Process(const io::SourceFrame& in) {
  FollowHint(in);
  CameraMessage m;
  m.camera = camera_index_;
  m.frame = in.frame;
  m.time_s = in.time_s;
  const cv::Rect window = UnconfirmedScan(in.frame) ? cv::Rect() : track_->Window(size_);
  bool full = window.empty();
  long guided = -1;
  bool guided_tried = false;  // the same fit on the whole frame would read the same pixels
  const cv::Mat* frame = Image(in, window);
  if (frame != nullptr) {
    CheckSize(frame->size(), in.frame);
    if (!full) {
      m.candidates = detector_(*frame, window);
      ++stats_.window_scans;
      full = !track_->Confirms(m.candidates);
      // Nothing accepted where the ball is expected: a guided fit there before the whole frame
      // (a camera that sees the ball only that way would otherwise search every frame whole).
      if (full) {
        guided = AddGuided(*frame, &m.candidates);
        guided_tried = true;
        full = guided < 0;
      } else {
        SearchBand(in, &m.candidates);
      }
    }
    if (full && !window.empty()) frame = Image(in, cv::Rect());
    if (frame == nullptr) {
      m.candidates.clear();
    } else if (full) {
      m.candidates = detector_(*frame, cv::Rect());
      ++stats_.full_scans;
    }
  }
  if (!guided_tried && frame != nullptr) guided = AddGuided(*frame, &m.candidates);
  track_->Update(m.candidates, guided >= 0 ? &m.candidates[guided] : nullptr);
  ++stats_.frames;
  for (const recon::BallObservation& o : m.candidates) stats_.candidates += !o.weak;
  return m;
}

}  // namespace fv::pipeline
