#include "fieldvision/pipeline/camera_stage.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>

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
  FV_REQUIRE(hidden_scan_every >= 0, "BallTrackOptions.hidden_scan_every must be >= 0 (got {})",
             hidden_scan_every);
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

namespace {
// A ball in this camera's image at a time.
struct Sighting {
  double time_s = 0.0;
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double radius_px = 0.0;
};
// Within two radii and 2 px: the same ball, as the tracking window takes it.
bool WithinTwoRadii(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius_px) {
  return (a - b).norm() <= 2.0 * radius_px + 2.0;
}
bool SameBall(const Sighting& a, const Sighting& b) {
  return WithinTwoRadii(a.centre_px, b.centre_px, std::max(a.radius_px, b.radius_px));
}
}  // namespace

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
    return best != nullptr && Near(best->centre_px, ExpectedCentre(), 0.0);
  }
  // Whether the window is where `e` expects the ball.
  bool Expects(const ExpectedBall& e) const {
    return active_ && Near(ExpectedCentre(), e.centre_px, e.radius_px);
  }
  // Whether a guided fit may look for the ball at its expected place (Expected).
  bool MayGuide() const { return o_.enabled && active_ && guided_run_ < o_.max_guided_frames; }
  Eigen::Vector2d ExpectedCentre() const { return centre_ + velocity_; }
  // Where the fusion expects the ball: taken unless the track expects it there too, or the track
  // was on the ball when the cameras together last saw it (`fused_then`: the fused position in
  // this camera at its time; a frame within `same_frame_s` of it): the track has seen the frames
  // since and knows of a bounce or a kick that the fusion's prediction does not.
  void Steer(const ExpectedBall& e, const std::optional<Sighting>& fused_then,
             double same_frame_s) {
    if (!o_.enabled) return;
    if (Expects(e) || (active_ && fused_then && Saw(*fused_then, same_frame_s))) return;
    centre_ = e.centre_px - e.step_px;
    velocity_ = e.step_px;
    radius_ = std::max(e.radius_px, 2.0);
    active_ = true;
  }
  double radius() const { return radius_; }
  int unconfirmed_scan_every() const { return o_.unconfirmed_scan_every; }
  int hidden_scan_every() const { return o_.hidden_scan_every; }
  // `guided`: the candidate of obs that a guided fit gave, or null.
  void Update(const std::vector<recon::BallObservation>& obs, const recon::BallObservation* guided,
              double time_s) {
    ++frames_;
    FrameSeen seen{time_s, {}, std::nullopt};
    for (const recon::BallObservation& o : obs) {
      if (!o.weak) seen.balls.push_back({time_s, o.centre_px, o.radius_px});
    }
    const recon::BallObservation* best = Best(obs);
    if (best != nullptr) {
      // A ball away from the expected place: another object, or the ball after a jump of the
      // track; the track starts anew.
      if (!active_ || !Near(best->centre_px, ExpectedCentre(), best->radius_px)) {
        track_since_s_ = time_s;
      }
      seen.track = Sighting{time_s, best->centre_px, best->radius_px};
    }
    frames_seen_.push_back(std::move(seen));
    if (frames_seen_.size() > kSeenKept) frames_seen_.pop_front();
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

  // Whether the frame at `f`'s time (within `same_frame_s`) was seen, without an accepted
  // candidate on `f`'s ball.
  bool MissedAt(const Sighting& f, double same_frame_s) const {
    const FrameSeen* seen = FrameAt(f.time_s, same_frame_s);
    return seen != nullptr && std::none_of(seen->balls.begin(), seen->balls.end(),
                                           [&](const Sighting& s) { return SameBall(s, f); });
  }

 private:
  static const recon::BallObservation* Best(const std::vector<recon::BallObservation>& obs) {
    const recon::BallObservation* best = nullptr;
    for (const recon::BallObservation& b : obs) {
      if (!b.weak && (best == nullptr || b.score > best->score)) best = &b;
    }
    return best;
  }
  // Within two radii (the larger of the track's and `radius_px`) and 2 px.
  bool Near(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius_px) const {
    return WithinTwoRadii(a, b, std::max(radius_, radius_px));
  }
  // Whether the track, on its present object, had its ball on `f`'s in the frame at `f`'s time
  // (within `same_frame_s`).
  bool Saw(const Sighting& f, double same_frame_s) const {
    const FrameSeen* seen = FrameAt(f.time_s, same_frame_s);
    return seen != nullptr && seen->time_s >= track_since_s_ && seen->track &&
           SameBall(*seen->track, f);
  }
  struct FrameSeen {
    double time_s;
    std::vector<Sighting> balls;    // the accepted candidates
    std::optional<Sighting> track;  // the one the track took
  };
  // The kept frame nearest `time_s` if within `same_frame_s` of it, else null.
  const FrameSeen* FrameAt(double time_s, double same_frame_s) const {
    const auto it = std::min_element(
        frames_seen_.begin(), frames_seen_.end(), [&](const FrameSeen& a, const FrameSeen& b) {
          return std::abs(a.time_s - time_s) < std::abs(b.time_s - time_s);
        });
    return it != frames_seen_.end() && std::abs(it->time_s - time_s) <= same_frame_s ? &*it
                                                                                     : nullptr;
  }
  static constexpr size_t kSeenKept = 16;  // frames: more than the hints' lag
  std::deque<FrameSeen> frames_seen_;      // the last frames
  // The time of the frame from which the track has followed its present object.
  double track_since_s_ = -std::numeric_limits<double>::infinity();
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
  hidden_ = false;
  if (!hint) return;
  const std::optional<ExpectedBall> e =
      ExpectBall(*hint, camera_, in.time_s, dt_s, hints_->options());
  if (!e) return;
  std::optional<Sighting> then;
  if (const auto at = ExpectBall(*hint, camera_, hint->time_s, 0.0, hints_->options())) {
    then = Sighting{hint->time_s, at->centre_px, at->radius_px};
  }
  const double same_frame_s = 0.5 * dt_s;
  track_->Steer(*e, then, same_frame_s);
  const double fresh_s = (hints_->options().lag_messages + 1.5) * dt_s;
  // Hidden: the cameras together follow the ball (a line through three positions at least, not a
  // jump) and saw it lately where this camera did not.
  hidden_ = hint->positions >= 3 && in.time_s - hint->time_s <= fresh_s && track_->Expects(*e) &&
            then && track_->MissedAt(*then, same_frame_s);
}

bool CameraStage::SkipWholeWhileHidden() {
  if (!hidden_) return false;
  const int every = track_->hidden_scan_every();
  return every > 1 && hidden_run_++ % every != 0;
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
  bool hidden_miss = false;   // the ball is hidden here and the window missed it (hidden_run_)
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
        hidden_miss = guided < 0 && hidden_;
        full = guided < 0 && !SkipWholeWhileHidden();
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
  track_->Update(m.candidates, guided >= 0 ? &m.candidates[guided] : nullptr, in.time_s);
  if (!hidden_miss) hidden_run_ = 0;
  ++stats_.frames;
  for (const recon::BallObservation& o : m.candidates) stats_.candidates += !o.weak;
  return m;
}

}  // namespace fv::pipeline
