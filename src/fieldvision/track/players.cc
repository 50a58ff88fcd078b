#include "fieldvision/track/players.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <set>
#include <thread>
#include <tuple>

#include <fmt/format.h>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/camera/frame_size.h"
#include "fieldvision/detect/lab.h"
#include "fieldvision/io/frame_source.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/track/players_internal.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/strings.h"

namespace fv::track {
namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// Reads frames (io/frame_source.h) in its own thread into a small queue (decoding overlaps
// detection). A read that fails (a truncated video) is rethrown by Next.
class FrameReader {
 public:
  FrameReader(const std::string& path, int max_frames, bool sequence) : max_frames_(max_frames) {
    io::FrameSourceOptions so;
    so.time = io::TimeSource::kContainer;
    if (sequence) so.fps = 25.0;  // the rate OpenCV reported for image patterns; --fps overrides
    // OpenCV's backends log their failures to stderr; the one-line error says it.
    const auto log_level = cv::utils::logging::getLogLevel();
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    try {
      source_ = io::OpenFrameSource(path, so);
    } catch (...) {
      cv::utils::logging::setLogLevel(log_level);
      throw;
    }
    cv::utils::logging::setLogLevel(log_level);
    fps_ = source_->fps();
    total_ = static_cast<int>(std::max(0LL, source_->FrameCount()));
    size_ = source_->FrameSize();
    frames_note_ = source_->FramesNote();  // decided on the first frame, read when opening
    thread_ = std::thread([this] { Run(); });
  }
  ~FrameReader() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  // Next frame and its container timestamp in ms (or frame / fps when the container has none),
  // or false at the end.
  bool Next(cv::Mat& frame, double& time_ms) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [&] { return !queue_.empty() || done_; });
    if (queue_.empty()) {
      if (!error_.empty()) Throw("{}", error_);
      return false;
    }
    frame = queue_.front();
    queue_.pop_front();
    time_ms = times_ms_.front();
    times_ms_.pop_front();
    cv_.notify_all();
    return true;
  }
  double fps() const { return fps_; }
  int total() const { return total_; }
  cv::Size size() const { return size_; }
  double read_seconds() const { return read_s_; }

  // FrameSource::FramesNote, taken when opening (the reading thread owns the source after).
  const std::string& frames_note() const { return frames_note_; }

 private:
  void Run() {
    int n = 0;
    std::string error;
    while (true) {
      if (max_frames_ > 0 && n >= max_frames_) break;
      cv::Mat f;
      long long index = 0;
      double time_s = 0;
      const auto t0 = Clock::now();
      bool ok = false;
      try {
        ok = source_->Read(&f, &index, &time_s);
      } catch (const std::exception& e) {
        error = e.what();
      }
      read_s_ += Seconds(t0, Clock::now());
      if (!ok || f.empty()) break;
      ++n;
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [&] { return queue_.size() < 8 || stop_; });
      if (stop_) break;
      queue_.push_back(std::move(f));
      times_ms_.push_back(1000.0 * time_s);
      cv_.notify_all();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = error;
    done_ = true;
    cv_.notify_all();
  }

  std::unique_ptr<io::FrameSource> source_;
  std::string error_;
  int max_frames_;
  double fps_ = 0;
  int total_ = 0;
  cv::Size size_;
  std::string frames_note_;
  double read_s_ = 0;
  std::deque<cv::Mat> queue_;
  std::deque<double> times_ms_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool done_ = false, stop_ = false;
  std::thread thread_;
};

// Detections read from a file (det.txt), frame by frame, filtered like a detector's.
class FileDetector : public PersonDetector {
 public:
  FileDetector(const std::string& path, const DetectorOptions& o, FootFilter filter)
      : file_(ReadDetectionsCsv(path)), o_(o), filter_(std::move(filter)), path_(path) {}
  std::vector<Detection> Detect(const cv::Mat&) override {
    const size_t f = next_++;
    if (f >= file_.frames.size()) return {};
    return FilterDetections(file_.frames[f], o_, filter_);
  }
  std::string name() const override { return "file " + path_; }
  // Throws naming the file when it has boxes beyond the `frames` of `video` that were read to
  // its end: they were dropped (a file of another video, or of a longer cut of it).
  void CheckAllUsed(int frames, const std::string& video) const {
    for (size_t f = frames; f < file_.frames.size(); ++f) {
      FV_REQUIRE(file_.frames[f].empty(),
                 "detections file '{}' has boxes in frame {} but video '{}' has {} frames "
                 "(detections of another video?)",
                 path_, f + 1, video, frames);
    }
  }

 private:
  DetectionsFile file_;
  DetectorOptions o_;
  FootFilter filter_;
  std::string path_;
  size_t next_ = 0;
};

bool ValidFps(double fps) { return std::isfinite(fps) && fps > 0 && fps < 10000; }

}  // namespace

FrameTimes TimesOfFrames(const std::vector<double>& container_ms, double container_fps,
                         double fps_override) {
  FrameTimes t;
  const size_t n = container_ms.size();
  if (n == 0) return t;
  auto by_rate = [&](double fps, const std::string& source) {
    t.fps = fps;
    t.source = source;
    t.time_s.resize(n);
    for (size_t i = 0; i < n; ++i) t.time_s[i] = i / fps;
    return t;
  };
  if (ValidFps(fps_override)) return by_rate(fps_override, fmt::format("--fps {:g}", fps_override));
  // Container timestamps: used when finite and strictly increasing (a backend without them
  // reports 0 for every frame).
  bool increasing = n >= 2;
  for (size_t i = 0; i < n && increasing; ++i) {
    increasing = std::isfinite(container_ms[i]) && container_ms[i] >= 0 &&
                 (i == 0 || container_ms[i] > container_ms[i - 1]);
  }
  if (increasing) {
    std::vector<double> steps;
    for (size_t i = 1; i < n; ++i) steps.push_back(container_ms[i] - container_ms[i - 1]);
    t.fps = 1000.0 / util::NearestRankPercentile(steps, 0.5);
    t.source = fmt::format("the video's timestamps (median {:.2f} frames/s)", t.fps);
    t.time_s.resize(n);
    for (size_t i = 0; i < n; ++i) t.time_s[i] = container_ms[i] / 1000.0;
    return t;
  }
  if (ValidFps(container_fps)) {
    return by_rate(container_fps,
                   fmt::format("the video's frame rate ({:g} frames/s)", container_fps));
  }
  t.source = "none (the video gives neither timestamps nor a frame rate: give --fps)";
  return t;
}

void StitchOptions::Check() const {
  CheckNonNegative(max_gap_s, "stitch max_gap_s");
  CheckNonNegative(reach_m, "stitch reach_m");
  CheckNonNegative(speed_slack_mps, "stitch speed_slack_mps");
  CheckNonNegative(max_speed_mps, "stitch max_speed_mps");
  CheckPositive(velocity_window_s, "stitch velocity_window_s");
  CheckNonNegative(height_window_s, "stitch height_window_s");
  CheckInRange(max_appearance_distance, 0.0, 1.0, "stitch max_appearance_distance");
  CheckNonNegative(border_px, "stitch border_px");
  CheckInRange(full_height_ratio, 0.0, 1.0, "stitch full_height_ratio");
  CheckPositive(person_height_m, "stitch person_height_m");
}

std::map<int, Tracklet> BuildTracklets(const std::vector<TrackRow>& rows, const StitchOptions& o,
                                       double fps, cv::Size image, const StitchCamera& cam) {
  std::map<int, Tracklet> tl;
  for (const auto& r : rows) tl[r.id].rows.push_back(&r);
  bool field = true;
  for (const auto& r : rows) field = field && r.x_m && r.y_m;
  const bool posed = cam.camera != nullptr && cam.camera->has_pose;
  // A box taller than it was measured (`height`, its top kept): the person's head is in view, the
  // legs hidden. Foot points of such boxes are mapped again when they can be: with a posed camera,
  // or in pixels without field positions; with field positions alone they cannot.
  const bool can_lengthen = posed || !field;
  // Ground position in metres of `r`'s box with `height` (at least its own): the field position,
  // else the foot pixel scaled by the box height.
  auto pos = [&](const TrackRow& r, double height) -> Eigen::Vector2d {
    cv::Rect2d box = r.box;
    box.height = std::max(box.height, height);
    if (posed && box.height > r.box.height) {
      if (const auto g = FootOnGround(*cam.camera, box, cam.foot_offset_m)) return *g;
    }
    if (field) return {*r.x_m, *r.y_m};
    const double s = o.person_height_m / std::max(1.0, box.height);
    return {(box.x + 0.5 * box.width) * s, (box.y + box.height) * s};
  };
  auto at_edge = [&](const cv::Rect2d& b, cv::Size size) {
    if (size.empty()) return false;
    return b.x <= o.border_px || b.y <= o.border_px || b.x + b.width >= size.width - o.border_px ||
           b.y + b.height >= size.height - o.border_px;
  };
  // A moving camera's rows lie on its canvas: at the border of their own frame or of the canvas
  // (people whose foot leaves it are not followed).
  auto at_border = [&](const TrackRow& r) {
    if (!cam.frame_box) return at_edge(r.box, image);
    return at_edge(cam.frame_box(r), image) || at_edge(r.box, cam.canvas_size);
  };
  auto clamp_speed = [&](const Eigen::Vector2d& v) {
    const double n = v.norm();
    return n > o.max_speed_mps ? Eigen::Vector2d(v * (o.max_speed_mps / n)) : v;
  };
  const int window = std::max(1, static_cast<int>(std::lround(o.velocity_window_s * fps)));
  const int height_window =
      std::max(window, static_cast<int>(std::lround(o.height_window_s * fps)));
  for (auto& entry : tl) {
    // Not a structured binding: clang 14 (make fuzz, make sanitize) cannot capture one.
    Tracklet& t = entry.second;
    t.id = entry.first;
    std::sort(t.rows.begin(), t.rows.end(),
              [](const TrackRow* a, const TrackRow* b) { return a->frame < b->frame; });
    const TrackRow& f = *t.rows.front();
    const TrackRow& l = *t.rows.back();
    // Ends: the rows within the velocity window of the first/last row. A box much shorter than
    // the person's height near that end (the median over height_window_s) is partly hidden and
    // its foot point is wrong: it is lengthened to that height where it can be, else left out.
    auto ends = [&](bool at_end) {
      const int end_frame = at_end ? l.frame : f.frame;
      std::vector<const TrackRow*> wide;  // from the end inwards, within height_window
      std::vector<double> hs;
      for (size_t k = 0; k < t.rows.size(); ++k) {
        const TrackRow* r = at_end ? t.rows[t.rows.size() - 1 - k] : t.rows[k];
        if (std::abs(r->frame - end_frame) > height_window) break;
        hs.push_back(r->box.height);
        wide.push_back(r);
      }
      const double height = util::NearestRankPercentile(hs, 0.5);
      // The rows used: those within `window` of the end when short boxes can be lengthened; else
      // the full boxes over `window` from the nearest one (all within it when there is none).
      std::vector<const TrackRow*> good;
      auto take_window = [&](bool full_only) {
        for (const TrackRow* r : wide) {
          if (full_only && r->box.height < o.full_height_ratio * height) continue;
          const int from = !full_only ? end_frame : good.empty() ? r->frame : good.front()->frame;
          if (std::abs(r->frame - from) > window) break;
          good.push_back(r);
        }
      };
      take_window(!can_lengthen);
      if (good.empty()) take_window(false);
      const TrackRow* anchor = good.front();
      const TrackRow* other = good.back();
      auto at = [&](const TrackRow* r) {
        return pos(*r, r->box.height < o.full_height_ratio * height ? height : 0.0);
      };
      const Eigen::Vector2d p = at(anchor);
      Eigen::Vector2d v = Eigen::Vector2d::Zero();
      if (anchor->frame != other->frame) {
        v = clamp_speed((p - at(other)) * fps / (anchor->frame - other->frame));
      }
      return std::make_tuple(anchor, p, v);
    };
    const auto [fa, pf, vf] = ends(false);
    const auto [la, pl, vl] = ends(true);
    t.first = pf;
    t.first_frame = fa->frame;
    t.v_first = vf;
    t.last = pl;
    t.last_frame = la->frame;
    t.v_last = vl;
    t.starts_at_border = at_border(f);
    t.ends_at_border = at_border(l);
  }
  return tl;
}

std::vector<TrackletLink> TrackletLinks(const std::map<int, Tracklet>& tl,
                                        const std::map<int, TrackAppearance>& appearance,
                                        const StitchOptions& o, double fps) {
  std::vector<TrackletLink> links;
  for (const auto& [ia, a] : tl) {
    const int a_end = a.rows.back()->frame;
    for (const auto& [ib, b] : tl) {
      if (ia == ib) continue;
      const int gap = b.rows.front()->frame - a_end;
      if (gap <= 0 || gap > o.max_gap_s * fps) continue;
      if (a.ends_at_border && b.starts_at_border) continue;
      const double gap_s = (b.first_frame - a.last_frame) / fps;
      const Eigen::Vector2d pa = a.last + 0.5 * gap_s * a.v_last;
      const Eigen::Vector2d pb = b.first - 0.5 * gap_s * b.v_first;
      const double limit = o.reach_m + o.speed_slack_mps * gap_s;
      const double d = (pa - pb).norm();
      if (!(d <= limit)) continue;  // NaN-safe: an undefined distance never links
      double app = 1.0;
      const auto ha = appearance.find(ia), hb = appearance.find(ib);
      if (ha != appearance.end() && hb != appearance.end() && ha->second.count > 0 &&
          hb->second.count > 0) {
        app = cv::compareHist(ha->second.sum / ha->second.count, hb->second.sum / hb->second.count,
                              cv::HISTCMP_BHATTACHARYYA);
      }
      if (!(app <= o.max_appearance_distance)) continue;  // NaN (a broken histogram) never links
      const double cost =
          d / std::max(1e-9, limit) + app / std::max(1e-9, o.max_appearance_distance);
      links.push_back({cost, ia, ib});
    }
  }
  std::sort(links.begin(), links.end(), [](const TrackletLink& x, const TrackletLink& y) {
    return x.cost != y.cost ? x.cost < y.cost : std::tie(x.a, x.b) < std::tie(y.a, y.b);
  });
  return links;
}

int JoinTracklets(const std::vector<TrackletLink>& links, std::vector<TrackRow>& rows) {
  std::set<int> has_next, has_prev;
  std::map<int, int> prev_of;
  int joins = 0;
  for (const TrackletLink& l : links) {
    if (has_next.count(l.a) || has_prev.count(l.b)) continue;
    has_next.insert(l.a);
    has_prev.insert(l.b);
    prev_of[l.b] = l.a;
    ++joins;
  }
  if (joins == 0) return 0;
  auto root = [&](int id) {
    while (prev_of.count(id)) id = prev_of[id];
    return id;
  };
  for (auto& r : rows) r.id = root(r.id);
  return joins;
}

int StitchTracklets(std::vector<TrackRow>& rows, const std::map<int, TrackAppearance>& appearance,
                    const StitchOptions& o, double fps, cv::Size image, const StitchCamera& cam) {
  o.Check();
  if (o.max_gap_s <= 0 || rows.empty()) return 0;
  fps = fps > 0 ? fps : 25.0;
  const std::map<int, Tracklet> tl = BuildTracklets(rows, o, fps, image, cam);
  const std::vector<TrackletLink> links = TrackletLinks(tl, appearance, o, fps);
  return JoinTracklets(links, rows);
}

void PlayersOptions::Check() const {
  detector.Check();
  tracker.Check();
  stitch.Check();
  hidden_feet.Check();
  smooth.Check();
  CheckNonNegative(field_margin_m, "field_margin_m");
  CheckNonNegative(max_frames, "max_frames");
  CheckNonNegative(interpolate_max_gap, "interpolate_max_gap");
  CheckNonNegative(min_track_frames, "min_track_frames");
  CheckNonNegative(fps, "fps");
  FV_REQUIRE(!moving_centre || moving_camera,
             "players: a camera that moves as well as turns (--moving-centre) needs "
             "--moving-camera");
  if (moving_camera) {
    camera_motion.Check();
    if (hold_to_lines) line_anchor.Check();
    FV_REQUIRE(detector.kind != "motion",
               "the motion detector needs a still camera, not a moving one (--moving-camera)");
  } else {
    view_drift.Check();
  }
}

std::string PlayersResult::Summary() const {
  const double f = std::max(1, frames);
  return fmt::format(
      "{} frames, time from {}; {} detections ({}), {} tracks ({} tracklets joined{}), {} rows "
      "({} interpolated, {} off the ground, {} partly hidden with their feet moved); "
      "{:.1f} s = {:.1f} frames/s (read {:.1f} ms/frame in its own thread, detect {:.1f}{}, "
      "track {:.1f}, map {:.1f}); tracker: {}{}{}{}{}{}{}{}",
      frames, time.source, detections, detector, tracks, stitched,
      dropped_tracks > 0 ? fmt::format(", {} dropped: seen in fewer than {} frames, "
                                       "--min-track-frames",
                                       dropped_tracks, min_track_frames)
                         : "",
      rows.size(), interpolated, off_ground, mended_feet, times.total_s,
      frames / std::max(1e-9, times.total_s), 1000 * times.read_s / f, 1000 * times.detect_s / f,
      camera_motion || view_drift ? fmt::format(", register {:.1f}", 1000 * times.register_s / f)
                                  : "",
      1000 * times.track_s / f, 1000 * times.map_s / f, tracker.Summary(),
      smoothing.tracks > 0 ? "; " + smoothing.Summary() : "",
      camera_motion ? "; " + camera_motion->Summary() : "",
      line_anchor ? "; " + line_anchor->Summary() : "",
      view_drift ? "; " + view_drift->Summary() : "",
      outside_frames > 0
          ? fmt::format(" ({} rows left out: beyond what their frame shows)", outside_frames)
          : "",
      beyond_canvas > 0 ? fmt::format("; {} detections in {} frames left out: beyond the canvas",
                                      beyond_canvas, beyond_canvas_frames)
                        : "",
      frames_note.empty() ? "" : "; " + frames_note);
}

int InterpolateGaps(std::vector<TrackRow>& rows, int max_gap, const camera::Camera* camera,
                    double foot_offset_m) {
  if (max_gap <= 0) return 0;
  std::map<int, std::vector<TrackRow>> by_id;
  for (const auto& r : rows) by_id[r.id].push_back(r);
  int added = 0;
  std::vector<TrackRow> extra;
  for (auto& [id, rs] : by_id) {
    std::sort(rs.begin(), rs.end(),
              [](const TrackRow& a, const TrackRow& b) { return a.frame < b.frame; });
    for (size_t i = 1; i < rs.size(); ++i) {
      const int gap = rs[i].frame - rs[i - 1].frame;
      if (gap <= 1 || gap - 1 > max_gap) continue;
      for (int f = rs[i - 1].frame + 1; f < rs[i].frame; ++f) {
        const double t = double(f - rs[i - 1].frame) / gap;
        TrackRow r;
        r.frame = f;
        r.id = id;
        const cv::Rect2d& a = rs[i - 1].box;
        const cv::Rect2d& b = rs[i].box;
        r.box = cv::Rect2d(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y),
                           a.width + t * (b.width - a.width), a.height + t * (b.height - a.height));
        r.conf = 0.0;
        if (camera != nullptr && camera->has_pose) {
          if (const auto g = FootOnGround(*camera, r.box, foot_offset_m)) {
            r.x_m = g->x();
            r.y_m = g->y();
          }
        }
        extra.push_back(r);
        ++added;
      }
    }
  }
  rows.insert(rows.end(), extra.begin(), extra.end());
  std::sort(rows.begin(), rows.end(), [](const TrackRow& a, const TrackRow& b) {
    return a.frame != b.frame ? a.frame < b.frame : a.id < b.id;
  });
  return added;
}

FootFilter FieldFootFilter(const camera::Camera& camera, const field::FieldModel* field,
                           double margin_m) {
  std::optional<field::FieldModel> f;
  if (field != nullptr) f = *field;
  const double margin = margin_m;
  return [cam = camera, f, margin](const cv::Point2d& foot) {  // copies: the filter outlives them
    const auto ray = cam.RayFromPixel({foot.x, foot.y});
    if (!ray) return false;
    const auto g = geometry::IntersectHorizontalPlane(*ray, 0.0);
    if (!g) return false;
    if (!f) return true;
    return std::abs(g->x()) <= 0.5 * f->length_m + margin &&
           std::abs(g->y()) <= 0.5 * f->width_m + margin;
  };
}

void AddTrackAppearance(const std::vector<TrackState>& states, const cv::Mat& frame,
                        double high_score, std::map<int, TrackAppearance>& appearance) {
  for (const auto& s : states) {
    if (s.predicted || s.score < high_score) continue;
    bool clear = true;
    for (const auto& o : states) {
      if (o.id != s.id && (o.box & s.box).area() > 0.1 * s.box.area()) clear = false;
    }
    if (!clear) continue;
    const cv::Mat h = TorsoHistogram(frame, s.box);
    if (h.empty()) continue;
    TrackAppearance& a = appearance[s.id];
    a.sum = a.sum.empty() ? h.clone() : a.sum + h;
    a.count++;
  }
}

std::optional<cv::Vec3f> TorsoColour(const cv::Mat& frame, const cv::Rect2d& box) {
  const cv::Rect torso = cv::Rect(cv::Rect2d(box.x + 0.3 * box.width, box.y + 0.2 * box.height,
                                             0.4 * box.width, 0.3 * box.height)) &
                         cv::Rect(0, 0, frame.cols, frame.rows);
  if (torso.area() <= 4) return std::nullopt;
  cv::Mat lab;
  detect::BgrToLab(frame(torso), &lab);
  const cv::Scalar m = cv::mean(lab);
  return cv::Vec3f(m[0] * 0.3, m[1], m[2]);  // chroma first
}

int DropShortTracks(std::vector<TrackRow>& rows, int min_frames) {
  std::map<int, int> count;
  for (const auto& r : rows) count[r.id]++;
  int dropped = 0;
  for (const auto& [id, n] : count) {
    if (n < min_frames) dropped++;
  }
  std::erase_if(rows, [&](const TrackRow& r) { return count[r.id] < min_frames; });
  return dropped;
}

std::map<int, int> AssignTeams(const std::map<int, std::vector<cv::Vec3f>>& torso_colours,
                               const std::set<int>& ids) {
  std::map<int, int> team_of;
  std::vector<int> team_ids;
  cv::Mat samples;
  for (const auto& [id, cs] : torso_colours) {
    if (!ids.count(id) || cs.empty()) continue;
    cv::Vec3f mean(0, 0, 0);
    for (const auto& c : cs) mean += c;
    mean /= static_cast<float>(cs.size());
    samples.push_back(cv::Mat(1, 3, CV_32F, &mean[0]).clone());
    team_ids.push_back(id);
  }
  if (samples.rows >= 2) {
    cv::Mat labels, centres;
    cv::kmeans(samples, 2, labels,
               cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3), 5,
               cv::KMEANS_PP_CENTERS, centres);
    for (size_t i = 0; i < team_ids.size(); ++i) team_of[team_ids[i]] = labels.at<int>(i);
  }
  return team_of;
}

namespace {

// What the pass over the frames gathers besides the rows.
struct PlayersPass {
  std::map<int, std::vector<cv::Vec3f>> torso_colours;
  std::map<int, TrackAppearance> appearance;
  std::vector<double> times_ms;
  DetectionsFile saved;
  // With a moving camera: the canvas the frames are tracked on (its homographies take the rows
  // back: their edge checks, TRACKS.csv, the overlay) and the image of it given to the tracker.
  std::optional<ViewCanvas> canvas;
  cv::Mat canvas_image;
  // Detections left out as their foot fell beyond the canvas, frames with such, the first one.
  int beyond_canvas = 0;
  int beyond_canvas_frames = 0;
  int first_beyond_canvas = 0;
};

// The detections' boxes.
std::vector<cv::Rect2d> Boxes(const std::vector<Detection>& dets) {
  std::vector<cv::Rect2d> boxes;
  boxes.reserve(dets.size());
  for (const Detection& d : dets) boxes.push_back(d.box);
  return boxes;
}

// A moving camera's frame: registered to the first one, its detections moved onto the canvas
// (those whose foot point then lies outside it or fails `filter` dropped) and the frame drawn
// there, where the tracker's appearance model reads it at the moved boxes.
const cv::Mat& ToCanvas(CameraMotion& motion, const FootFilter& filter, const cv::Mat& frame,
                        std::vector<Detection>& dets, PlayersPass& pass) {
  ViewCanvas& canvas = *pass.canvas;
  canvas.AddFrame(motion.Register(frame, Boxes(dets)));
  const int index = canvas.frames() - 1;
  std::vector<Detection> kept;
  int beyond = 0;
  for (Detection d : dets) {
    d.box = canvas.BoxToCanvas(index, d.box);
    const cv::Point2d foot(d.box.x + 0.5 * d.box.width, d.box.y + d.box.height);
    const bool on_field = !filter || filter(foot);
    if (!FootInView(d.box, canvas.size())) {
      // Counted where the field filter keeps it, or where no canvas pixel holds it at all.
      if (on_field || !std::isfinite(foot.x) || !std::isfinite(foot.y)) ++beyond;
      continue;
    }
    if (on_field) kept.push_back(d);
  }
  dets = std::move(kept);
  if (beyond > 0) {
    pass.beyond_canvas += beyond;
    if (pass.beyond_canvas_frames++ == 0) pass.first_beyond_canvas = index + 1;
  }
  canvas.Draw(index, frame, pass.canvas_image);
  return pass.canvas_image;
}

// One frame's tracks as rows (1-based frame `frame_number`), with their torso colours for teams.
void RecordTracks(const std::vector<TrackState>& states, const cv::Mat& frame, int frame_number,
                  bool calibrated, const PlayersOptions& options, PlayersResult& result,
                  PlayersPass& pass) {
  for (const auto& s : states) {
    TrackRow r;
    r.frame = frame_number;  // MOTChallenge numbering
    r.id = s.id;
    r.box = s.box;
    r.conf = s.score;
    if (calibrated) {
      if (s.field_m) {
        r.x_m = s.field_m->x();
        r.y_m = s.field_m->y();
      } else {
        result.off_ground++;
      }
    }
    result.rows.push_back(r);
    if (options.teams && !s.predicted) {
      if (const auto c = TorsoColour(frame, s.box)) pass.torso_colours[s.id].push_back(*c);
    }
  }
}

// The ids that have rows.
std::set<int> TrackIds(const std::vector<TrackRow>& rows) {
  std::set<int> ids;
  for (const TrackRow& r : rows) ids.insert(r.id);
  return ids;
}

// After the pass: short tracks dropped, tracklets joined, gaps filled, ground tracks smoothed,
// teams and the rows' times.
void FinishTracks(const PlayersOptions& options, const camera::Camera* camera, bool calibrated,
                  cv::Size image, const PlayersPass& pass, bool sequence, double video_fps,
                  PlayersResult& result) {
  const int frames = result.frames;
  // Short tracks are usually false detections; on a short clip the minimum is half the clip.
  result.min_track_frames = std::min(options.min_track_frames, std::max(1, (frames + 1) / 2));
  if (options.min_track_frames > 0) {
    result.dropped_tracks = DropShortTracks(result.rows, result.min_track_frames);
  }
  // A moving camera's rows are on its canvas; the checks at the image's edges take each box back
  // to its own frame's.
  FrameBoxOf frame_box;
  cv::Size canvas_size;
  if (pass.canvas) {
    frame_box = [&pass](const TrackRow& r) { return pass.canvas->BoxToFrame(r.frame - 1, r.box); };
    canvas_size = pass.canvas->size();
  }
  result.stitched = StitchTracklets(
      result.rows, pass.appearance, options.stitch, result.fps, image,
      {calibrated ? camera : nullptr, options.tracker.foot_offset_m, frame_box, canvas_size});
  result.interpolated =
      InterpolateGaps(result.rows, options.interpolate_max_gap, calibrated ? camera : nullptr,
                      options.tracker.foot_offset_m);
  if (calibrated) {
    // Rows with a detection are measurements; carried and interpolated ones (conf 0) are not.
    std::vector<bool> measured(result.rows.size());
    for (size_t i = 0; i < result.rows.size(); ++i) measured[i] = result.rows[i].conf > 0;
    result.mended_feet =
        MendHiddenFeet(result.rows, measured, *camera, options.tracker.foot_offset_m, result.fps,
                       options.hidden_feet, frame_box);
    result.smoothing =
        SmoothGroundTracks(result.rows, measured, *camera, result.fps, options.smooth);
  }
  const std::set<int> ids = TrackIds(result.rows);
  result.tracks = static_cast<int>(ids.size());
  if (options.teams) result.team_of = AssignTeams(pass.torso_colours, ids);
  // An image sequence has no time of its own (OpenCV reports 25 frames/s for any pattern).
  if (sequence) {
    result.time = TimesOfFrames(std::vector<double>(pass.times_ms.size(), 0.0), 0.0, options.fps);
    if (result.time.time_s.empty()) {
      result.time.source = "none (an image sequence has no frame rate: give --fps)";
    }
  } else {
    result.time = TimesOfFrames(pass.times_ms, video_fps, options.fps);
  }
  if (!result.time.time_s.empty()) {
    for (auto& r : result.rows) r.time_s = result.time.time_s[r.frame - 1];
  }
}

}  // namespace

// The first view's undistorted pixels to the ground by its pose: w > 0 where the frame's ray meets
// the ground ahead of it (PixelsFromGround's scale); kInsetM inside the surround's edge, where the
// far side's boards stand. Goals (on the goal lines) and boards between the camera and the field
// are not left out: rays through them meet the ground inside the area.
CameraMotion::FeatureFilter OnTheGround(const camera::Camera& first,
                                        const field::FieldModel& field) {
  constexpr double kInsetM = 0.3;
  const cv::Matx33d ground_from_first = PixelsFromGround(first).inv();
  const double hx = field.HalfLengthWithSurround() - kInsetM;
  const double hy = field.HalfWidthWithSurround() - kInsetM;
  return [ground_from_first, hx, hy](const cv::Vec3d& first_px) {
    const cv::Vec3d g = ground_from_first * first_px;
    return g[2] > 0 && std::abs(g[0]) <= hx * g[2] && std::abs(g[1]) <= hy * g[2];
  };
}

namespace {

// A moving camera's registration (held to the field's lines when it has them and the camera a
// pose; on the ground alone for a camera that moves as well as turns) and its canvas.
void SetUpMovingCamera(const camera::Camera* camera, const field::FieldModel* field,
                       const PlayersOptions& options, cv::Size size,
                       std::optional<CameraMotion>& motion, std::optional<LineAnchor>& anchor,
                       PlayersPass& pass) {
  const bool calibrated = camera != nullptr && camera->has_pose;
  motion.emplace(options.camera_motion, camera);
  LineAnchorOptions anchor_options = options.line_anchor;
  if (options.moving_centre) {
    FV_REQUIRE(calibrated && field != nullptr,
               "players: a camera that moves as well as turns (--moving-centre) needs a posed "
               "camera file and a field (--field)");
    motion->SetFeatureFilter(OnTheGround(*camera, *field));
    anchor_options.refine.fix_centre = false;
  }
  if (options.hold_to_lines && calibrated && field != nullptr && field->HasPaintedLines()) {
    anchor.emplace(*camera, *field, anchor_options);
    motion->SetAnchor([&anchor](const cv::Mat& bgr, const std::vector<cv::Rect2d>& people,
                                const cv::Matx33d& registered, bool keyframe) {
      return anchor->Correct(bgr, people, registered, keyframe);
    });
  }
  const double margin = options.camera_motion.canvas_margin;
  pass.canvas =
      camera != nullptr ? ViewCanvas(*camera, margin) : ViewCanvas::Uncalibrated(size, margin);
}

// A moving camera's rows back in each frame's own pixels; a row carried or filled in beyond what
// its frame can show (behind its view) has no box there: left out, with a track left without
// rows and its team.
void BoxesBackToFrames(const ViewCanvas& canvas, PlayersResult& result) {
  for (TrackRow& r : result.rows) r.box = canvas.BoxToFrame(r.frame - 1, r.box);
  const auto outside = std::remove_if(result.rows.begin(), result.rows.end(),
                                      [](const TrackRow& r) { return !BoxInRange(r.box); });
  result.outside_frames = static_cast<int>(result.rows.end() - outside);
  result.rows.erase(outside, result.rows.end());
  const std::set<int> ids = TrackIds(result.rows);
  result.tracks = static_cast<int>(ids.size());
  std::erase_if(result.team_of, [&ids](const auto& entry) { return !ids.contains(entry.first); });
}

}  // namespace

PlayersResult RunPlayers(const std::string& video, const camera::Camera* camera,
                         const field::FieldModel* field, const PlayersOptions& options) {
  options.Check();
  const auto t_start = Clock::now();
  const bool calibrated = camera != nullptr && camera->has_pose;
  // Open the video first: a bad video is reported before the model is loaded.
  // An image sequence is read up to its last file (reading past it makes OpenCV warn).
  const size_t sequence_files = io::ListImageSequence(video).size();
  int frame_limit = options.max_frames;
  if (sequence_files > 0) {
    const int n = static_cast<int>(sequence_files);
    frame_limit = frame_limit > 0 ? std::min(frame_limit, n) : n;
  }
  FrameReader reader(video, frame_limit, sequence_files > 0);
  // The camera fitted to the frames (an encoder's cropped padding; else an error).
  std::optional<camera::Camera> fitted;
  std::string camera_note;
  if (camera != nullptr) {
    fitted = *camera;
    camera_note = camera::FitCameraToFrames(
        *fitted, fmt::format("camera '{}'", camera->name.empty() ? "(unnamed)" : camera->name),
        reader.size().width, reader.size().height, fmt::format("video '{}'", video));
    camera = &*fitted;
  }
  // A moving camera's frames are tracked on its canvas, as the canvas's camera.
  PlayersPass pass;
  std::optional<CameraMotion> motion;
  std::optional<LineAnchor> anchor;
  if (options.moving_camera) {
    SetUpMovingCamera(camera, field, options, reader.size(), motion, anchor, pass);
  }
  const camera::Camera* tracked =
      pass.canvas && camera != nullptr ? &pass.canvas->camera() : camera;
  FootFilter filter;
  if (calibrated) filter = FieldFootFilter(*tracked, field, options.field_margin_m);
  std::unique_ptr<PersonDetector> detector;
  const FileDetector* from_file = nullptr;
  if (!options.detections_in.empty()) {
    options.detector.Check();
    // A moving camera's feet are judged on its canvas (ToCanvas).
    auto file = std::make_unique<FileDetector>(options.detections_in, options.detector,
                                               options.moving_camera ? FootFilter() : filter);
    from_file = file.get();
    detector = std::move(file);
  } else {
    detector = MakeDetector(options.detector, calibrated ? camera : nullptr,
                            options.moving_camera ? FootFilter() : filter);
  }
  PlayersResult result;
  result.detector = detector->name();
  // The tracker's and stitcher's rate (frame steps to seconds); the rows' times come from
  // TimesOfFrames after the pass.
  result.fps = options.fps > 0 ? options.fps : (ValidFps(reader.fps()) ? reader.fps() : 25.0);
  TrackerOptions topt = options.tracker;
  topt.fps = result.fps;
  ByteTracker tracker(topt, calibrated ? tracked : nullptr);
  long long total = reader.total();
  if (options.max_frames > 0 && (total <= 0 || total > options.max_frames)) {
    total = options.max_frames;
  }
  util::Progress progress("players", total, "frames", options.progress);
  // A still run's view is checked for moves (a camera knocked, swaying or panning).
  std::optional<ViewDrift> drift;
  if (!motion) drift.emplace(options.view_drift);
  cv::Mat frame;
  int index = 0;
  double time_ms = 0;
  while (reader.Next(frame, time_ms)) {
    pass.times_ms.push_back(time_ms);
    const auto t0 = Clock::now();
    std::vector<Detection> dets = detector->Detect(frame);
    if (!options.detections_out.empty()) pass.saved.frames.push_back(dets);  // the frame's pixels
    const auto t_register = Clock::now();
    const cv::Mat view = motion ? ToCanvas(*motion, filter, frame, dets, pass) : frame;
    if (drift) drift->Add(index, frame, Boxes(dets));
    const auto t1 = Clock::now();
    result.times.register_s += Seconds(t_register, t1);
    const std::vector<TrackState> states = tracker.Update(dets, view);
    const auto t2 = Clock::now();
    result.detections += static_cast<int>(dets.size());
    // Appearance of each track for stitching: confident boxes that no other box overlaps.
    if (options.stitch.max_gap_s > 0) {
      AddTrackAppearance(states, view, options.tracker.high_score, pass.appearance);
    }
    RecordTracks(states, view, index + 1, calibrated, options, result, pass);
    result.times.detect_s += Seconds(t0, t_register);
    result.times.track_s += std::chrono::duration<double>(t2 - t1).count();
    ++index;
    progress.Update(index);
  }
  progress.Finish();
  result.frames = index;
  FV_REQUIRE(index > 0, "video '{}' has no readable frame", video);
  // Read to the video's end (not cut by --max-frames): the file's boxes after it were dropped.
  if (from_file != nullptr && (options.max_frames <= 0 || index < options.max_frames)) {
    from_file->CheckAllUsed(index, video);
  }
  if (!options.detections_out.empty()) WriteDetectionsCsv(pass.saved, options.detections_out);
  const auto t_map = Clock::now();
  FinishTracks(options, tracked, calibrated, reader.size(), pass, sequence_files > 0, reader.fps(),
               result);
  if (motion) {
    BoxesBackToFrames(*pass.canvas, result);
    result.beyond_canvas = pass.beyond_canvas;
    result.beyond_canvas_frames = pass.beyond_canvas_frames;
    result.first_beyond_canvas = pass.first_beyond_canvas;
    result.camera_motion = motion->stats();
    if (anchor) result.line_anchor = anchor->stats();
    result.canvas = std::move(pass.canvas);
  }
  if (drift) result.view_drift = drift->stats();
  result.times.map_s = Seconds(t_map, Clock::now());
  result.times.read_s = reader.read_seconds();
  result.frames_note = util::JoinNonEmpty({camera_note, reader.frames_note()}, "; ");
  result.tracker = tracker.stats();
  result.times.total_s = Seconds(t_start, Clock::now());
  return result;
}

}  // namespace fv::track
