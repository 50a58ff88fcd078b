#include "fieldvision/track/bytetrack.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/track/bytetrack_internal.h"
#include "fieldvision/track/hungarian.h"
#include "fieldvision/util/error.h"

namespace fv::track {

void TrackerOptions::Check() const {
  CheckInRange(high_score, 0.0, 1.0, "high_score");
  CheckInRange(low_score, 0.0, 1.0, "low_score");
  FV_REQUIRE(low_score <= high_score, "low_score ({}) must be <= high_score ({})", low_score,
             high_score);
  CheckInRange(new_track_score, 0.0, 1.0, "new_track_score");
  CheckInRange(match_iou, 0.0, 1.0, "match_iou");
  CheckInRange(low_match_iou, 0.0, 1.0, "low_match_iou");
  CheckPositive(field_gate_m, "field_gate_m");
  CheckInRange(field_weight, 0.0, 1.0, "field_weight");
  CheckNonNegative(max_lost_frames, "max_lost_frames");
  FV_REQUIRE(min_hits >= 1, "min_hits must be >= 1 (got {})", min_hits);
  CheckInRange(reid_max_distance, 0.0, 1.0, "reid_max_distance");
  CheckPositive(reid_speed_mps, "reid_speed_mps");
  CheckPositive(reid_speed_px, "reid_speed_px");
  CheckPositive(fps, "fps");
  CheckInRange(appearance_weight, 0.0, 1.0, "appearance_weight");
  CheckInRange(appearance_momentum, 0.0, 1.0, "appearance_momentum");
  CheckInRange(foot_offset_m, 0.0, 1.0, "foot_offset_m");
  FV_REQUIRE(sot == "none" || sot == "csrt" || sot == "kcf" || sot == "mosse",
             "sot '{}' is not one of none, csrt, kcf, mosse", sot);
}

std::string TrackerStats::Summary() const {
  return fmt::format("{} frames, {} tracks, {} re-found by appearance, {} + {} matches (high, low)",
                     frames, tracks_started, refound, first_stage_matches, second_stage_matches);
}

std::optional<Eigen::Vector2d> GroundBelowPixel(const camera::Camera& camera,
                                                const Eigen::Vector2d& uv, double height_m,
                                                double offset_m) {
  const auto ray = camera.RayFromPixel(uv);
  if (!ray) return std::nullopt;
  const auto p = geometry::IntersectHorizontalPlane(*ray, height_m);
  if (!p) return std::nullopt;
  Eigen::Vector2d g = p->head<2>();
  const Eigen::Vector2d away = g - camera.CentreInWorld().head<2>();
  if (offset_m != 0.0 && away.norm() > 1e-6) g += offset_m * away.normalized();
  return g;
}

std::optional<Eigen::Vector2d> FootOnGround(const camera::Camera& camera, const cv::Rect2d& box,
                                            double offset_m) {
  return GroundBelowPixel(camera, {box.x + 0.5 * box.width, box.y + box.height}, 0.0, offset_m);
}

cv::Mat TorsoHistogram(const cv::Mat& bgr, const cv::Rect2d& box) {
  if (bgr.empty()) return {};
  const cv::Rect2d torso(box.x + 0.25 * box.width, box.y + 0.2 * box.height, 0.5 * box.width,
                         0.35 * box.height);
  const cv::Rect r = cv::Rect(torso) & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (r.width < 2 || r.height < 2) return {};
  cv::Mat hsv;
  cv::cvtColor(bgr(r), hsv, cv::COLOR_BGR2HSV);
  const int channels[] = {0, 1};
  const int sizes[] = {16, 8};
  const float h_range[] = {0, 180}, s_range[] = {0, 256};
  const float* ranges[] = {h_range, s_range};
  cv::Mat hist;
  cv::calcHist(&hsv, 1, channels, cv::Mat(), hist, 2, sizes, ranges);
  cv::normalize(hist, hist, 1.0, 0.0, cv::NORM_L1);
  return hist;
}

namespace {

// Kalman noise relative to the box height, as in ByteTrack.
constexpr double kStdPos = 1.0 / 20, kStdVel = 1.0 / 160;

cv::Mat Xyah(const cv::Rect2d& b) {
  return (cv::Mat_<float>(4, 1) << b.x + 0.5 * b.width, b.y + 0.5 * b.height,
          b.width / std::max(1e-6, b.height), b.height);
}

cv::Rect2d BoxOf(const cv::Mat& s) {
  const double h = s.at<float>(3), w = s.at<float>(2) * h;
  return {s.at<float>(0) - 0.5 * w, s.at<float>(1) - 0.5 * h, w, h};
}

}  // namespace

void ByteTracker::Track::Init(const cv::Rect2d& b) {
  cv::setIdentity(kf.transitionMatrix);
  for (int i = 0; i < 4; ++i) kf.transitionMatrix.at<float>(i, i + 4) = 1.0f;
  kf.measurementMatrix = cv::Mat::zeros(4, 8, CV_32F);
  for (int i = 0; i < 4; ++i) kf.measurementMatrix.at<float>(i, i) = 1.0f;
  kf.statePost = cv::Mat::zeros(8, 1, CV_32F);
  Xyah(b).copyTo(kf.statePost.rowRange(0, 4));
  const double h = b.height;
  const double sd[8] = {2 * kStdPos * h,  2 * kStdPos * h,  1e-2, 2 * kStdPos * h,
                        10 * kStdVel * h, 10 * kStdVel * h, 1e-5, 10 * kStdVel * h};
  kf.errorCovPost = cv::Mat::zeros(8, 8, CV_32F);
  for (int i = 0; i < 8; ++i) kf.errorCovPost.at<float>(i, i) = float(sd[i] * sd[i]);
  box = b;
}

void ByteTracker::Track::Predict() {
  if (state != TrackPhase::kTracked) kf.statePost.at<float>(7) = 0;  // lost: no height change
  const double h = std::max(1.0f, kf.statePost.at<float>(3));
  const double sd[8] = {kStdPos * h, kStdPos * h, 1e-2, kStdPos * h,
                        kStdVel * h, kStdVel * h, 1e-5, kStdVel * h};
  kf.processNoiseCov = cv::Mat::zeros(8, 8, CV_32F);
  for (int i = 0; i < 8; ++i) kf.processNoiseCov.at<float>(i, i) = float(sd[i] * sd[i]);
  const cv::Mat s = kf.predict();
  box = BoxOf(s);
}

void ByteTracker::Track::Correct(const cv::Rect2d& b) {
  const double h = std::max(1.0f, kf.statePre.at<float>(3));
  const double sd[4] = {kStdPos * h, kStdPos * h, 1e-1, kStdPos * h};
  kf.measurementNoiseCov = cv::Mat::zeros(4, 4, CV_32F);
  for (int i = 0; i < 4; ++i) kf.measurementNoiseCov.at<float>(i, i) = float(sd[i] * sd[i]);
  box = BoxOf(kf.correct(Xyah(b)));
}

void ByteTracker::Track::ResetSot() {
  sot.reset();
  sot_legacy.reset();
}

FrameDetections SortDetections(const std::vector<Detection>& detections, const cv::Mat& frame,
                               const TrackerOptions& o, const camera::Camera* camera) {
  const size_t n = detections.size();
  FrameDetections fd;
  fd.field_m.resize(n);
  if (camera != nullptr) {
    for (size_t i = 0; i < n; ++i) {
      fd.field_m[i] = FootOnGround(*camera, detections[i].box, o.foot_offset_m);
    }
  }
  for (int i = 0; i < int(n); ++i) {
    if (detections[i].score >= o.high_score) {
      fd.high.push_back(i);
    } else if (detections[i].score >= o.low_score) {
      fd.low.push_back(i);
    }
  }
  fd.used.assign(n, 0);
  // Torso histograms of the high-score detections (appearance cost), and whether another
  // detection overlaps each (then its histogram mixes two people and does not update tracks).
  fd.hist.resize(n);
  fd.clear.assign(n, 1);
  for (int i : fd.high) {
    if (!frame.empty()) fd.hist[i] = TorsoHistogram(frame, detections[i].box);
    for (int j = 0; j < int(n); ++j) {
      if (j != i && detections[j].score >= o.low_score &&
          (detections[i].box & detections[j].box).area() > 0.1 * detections[i].box.area()) {
        fd.clear[i] = 0;
      }
    }
  }
  return fd;
}

bool LeftImage(const ByteTracker::Track& t, const cv::Size& frame) {
  const cv::Point2d c(t.box.x + 0.5 * t.box.width, t.box.y + t.box.height);
  return c.x < 0 || c.y < 0 || c.x >= frame.width || c.y >= frame.height + 0.25 * t.box.height;
}

double PairCost(const ByteTracker::Track& t, const std::vector<Detection>& detections,
                const FrameDetections& fd, int d, double min_iou, bool full,
                const TrackerOptions& o) {
  const double iou = Iou(t.box, detections[d].box);
  double motion;
  if (!full || !t.field_m || !fd.field_m[d] || o.field_weight <= 0) {
    if (iou < min_iou) return 1e9;
    motion = 1.0 - iou;
  } else {
    // The gate grows with the time lost by how far a person may have gone, up to 3 gates.
    const double gate =
        std::min(3.0 * o.field_gate_m, o.field_gate_m + o.reid_speed_mps * t.lost_frames / o.fps);
    const double dist = (*t.field_m - *fd.field_m[d]).norm();
    if (dist > gate || (iou < min_iou && dist > 0.5 * gate)) return 1e9;
    motion = (1 - o.field_weight) * (1 - iou) + o.field_weight * dist / gate;
  }
  if (!full || o.appearance_weight <= 0 || t.hist.empty() || fd.hist[d].empty()) return motion;
  const double app = cv::compareHist(t.hist, fd.hist[d], cv::HISTCMP_BHATTACHARYYA);
  return (1 - o.appearance_weight) * motion + o.appearance_weight * app;
}

bool InReidReach(const ByteTracker::Track& t, const Detection& det,
                 const std::optional<Eigen::Vector2d>& det_field_m, const TrackerOptions& o) {
  if (t.field_m && det_field_m) {
    const double reach = o.reid_speed_mps * t.lost_frames / o.fps + 1.0;
    return (*t.field_m - *det_field_m).norm() <= reach;
  }
  const cv::Point2d a(t.box.x + 0.5 * t.box.width, t.box.y + t.box.height);
  const cv::Point2d b(det.box.x + 0.5 * det.box.width, det.box.y + det.box.height);
  return cv::norm(a - b) <= o.reid_speed_px * t.lost_frames + det.box.height;
}

ByteTracker::ByteTracker(const TrackerOptions& options, const camera::Camera* camera)
    : o_(options) {
  o_.Check();
  if (camera != nullptr && camera->has_pose) camera_ = *camera;
}

ByteTracker::~ByteTracker() = default;

void ByteTracker::PredictTracks(const cv::Mat& frame) {
  for (auto& t : tracks_) {
    t->matched = false;
    t->sot_box = false;
    t->Predict();
    if (camera_) t->field_m = FootOnGround(*camera_, t->box, o_.foot_offset_m);
    // A lost track whose prediction left the image has left the scene: a person coming back
    // later is a new track (as in the MOTChallenge annotations).
    if (t->state == TrackPhase::kLost && !frame.empty() && LeftImage(*t, frame.size())) {
      t->lost_frames = o_.max_lost_frames + 1;
    }
  }
}

void ByteTracker::DropExpired() {
  std::erase_if(tracks_, [&](const std::unique_ptr<Track>& t) {
    return t->lost_frames > o_.max_lost_frames;
  });
}

void ByteTracker::Apply(Track& t, int d, const std::vector<Detection>& detections,
                        FrameDetections& fd) {
  t.Correct(detections[d].box);
  t.matched = true;
  t.score = detections[d].score;
  t.hits++;
  t.lost_frames = 0;
  t.ResetSot();
  if (camera_) t.field_m = FootOnGround(*camera_, t.box, o_.foot_offset_m);
  if (!fd.hist[d].empty() && (fd.clear[d] || t.hist.empty())) {
    const cv::Mat& h = fd.hist[d];
    t.hist = t.hist.empty() ? h.clone()
                            : (1 - o_.appearance_momentum) * t.hist + o_.appearance_momentum * h;
  }
  fd.used[d] = 1;
}

int ByteTracker::Associate(const std::vector<Track*>& ts, const std::vector<int>& ds,
                           double min_iou, bool full, const std::vector<Detection>& detections,
                           FrameDetections& fd) {
  std::vector<std::vector<double>> cost(ts.size(), std::vector<double>(ds.size()));
  for (size_t i = 0; i < ts.size(); ++i) {
    for (size_t j = 0; j < ds.size(); ++j) {
      cost[i][j] = PairCost(*ts[i], detections, fd, ds[j], min_iou, full, o_);
    }
  }
  const std::vector<int> a = SolveAssignment(cost);
  int n = 0;
  for (size_t i = 0; i < ts.size(); ++i) {
    if (a[i] >= 0) {
      Apply(*ts[i], ds[a[i]], detections, fd);
      ++n;
    }
  }
  return n;
}

void ByteTracker::AssociateAll(const std::vector<Detection>& detections, FrameDetections& fd) {
  // Stage 1: confirmed tracks (tracked and lost) with high-score detections.
  std::vector<Track*> pool;
  for (auto& t : tracks_) {
    if (t->state != TrackPhase::kNew) pool.push_back(t.get());
  }
  stats_.first_stage_matches += Associate(pool, fd.high, o_.match_iou, true, detections, fd);
  // Stage 2: tracked tracks left with low-score detections (IoU only, as in ByteTrack).
  std::vector<Track*> left;
  for (Track* t : pool) {
    if (!t->matched && t->state == TrackPhase::kTracked) left.push_back(t);
  }
  stats_.second_stage_matches += Associate(left, fd.low, o_.low_match_iou, false, detections, fd);
  // Unconfirmed tracks with the high-score detections left.
  std::vector<Track*> fresh;
  for (auto& t : tracks_) {
    if (t->state == TrackPhase::kNew) fresh.push_back(t.get());
  }
  std::vector<int> high_left;
  for (int d : fd.high) {
    if (!fd.used[d]) high_left.push_back(d);
  }
  Associate(fresh, high_left, 0.3, true, detections, fd);
}

bool ByteTracker::CarryBySot(Track& t, const cv::Mat& frame) {
  if (!t.sot && !t.sot_legacy && !previous_frame_.empty()) {
    const cv::Rect init = cv::Rect(t.box) & cv::Rect(0, 0, frame.cols, frame.rows);
    if (init.width > 4 && init.height > 4) {
      if (o_.sot == "csrt") t.sot = cv::TrackerCSRT::create();
      if (o_.sot == "kcf") t.sot = cv::TrackerKCF::create();
      if (o_.sot == "mosse") t.sot_legacy = cv::legacy::TrackerMOSSE::create();
      if (t.sot) t.sot->init(previous_frame_, init);
      if (t.sot_legacy) t.sot_legacy->init(previous_frame_, cv::Rect2d(init));
    }
  }
  bool carried = false;
  if (t.sot) {
    cv::Rect r;
    if (t.sot->update(frame, r)) {
      t.Correct(cv::Rect2d(r));
      carried = true;
    }
  } else if (t.sot_legacy) {
    cv::Rect2d r;
    if (t.sot_legacy->update(frame, r)) {
      t.Correct(r);
      carried = true;
    }
  }
  if (carried && camera_) t.field_m = FootOnGround(*camera_, t.box, o_.foot_offset_m);
  if (!carried) t.ResetSot();
  return carried;
}

void ByteTracker::ConfirmOrMiss(const cv::Mat& frame) {
  for (auto& t : tracks_) {
    if (t->matched) {
      if (t->state == TrackPhase::kLost) t->state = TrackPhase::kTracked;
      if (t->state == TrackPhase::kNew && (t->hits >= o_.min_hits)) {
        t->state = TrackPhase::kTracked;
        t->id = next_id_++;
        ++stats_.tracks_started;
      }
      continue;
    }
    if (t->state == TrackPhase::kNew) {
      t->lost_frames = 1 << 20;  // unconfirmed and missed: dropped below
      continue;
    }
    const bool carried = o_.sot != "none" && t->state == TrackPhase::kTracked && !frame.empty() &&
                         CarryBySot(*t, frame);
    t->sot_box = carried;
    t->lost_frames++;
    if (!carried) t->state = TrackPhase::kLost;
  }
}

void ByteTracker::RefindOrStart(const std::vector<Detection>& detections, FrameDetections& fd,
                                const cv::Mat& frame) {
  std::vector<int> unmatched;
  for (int d : fd.high) {
    if (!fd.used[d] && detections[d].score >= o_.new_track_score) unmatched.push_back(d);
  }
  std::vector<Track*> lost;
  for (auto& t : tracks_) {
    if (t->state == TrackPhase::kLost && !t->matched && !t->hist.empty() &&
        t->lost_frames <= o_.max_lost_frames) {
      lost.push_back(t.get());
    }
  }
  if (!lost.empty() && !unmatched.empty() && !frame.empty()) {
    std::vector<cv::Mat> hists(unmatched.size());
    for (size_t j = 0; j < unmatched.size(); ++j) {
      hists[j] = TorsoHistogram(frame, detections[unmatched[j]].box);
    }
    std::vector<std::vector<double>> cost(lost.size(), std::vector<double>(unmatched.size(), 1e9));
    for (size_t i = 0; i < lost.size(); ++i) {
      for (size_t j = 0; j < unmatched.size(); ++j) {
        const int d = unmatched[j];
        if (hists[j].empty() || !InReidReach(*lost[i], detections[d], fd.field_m[d], o_)) continue;
        const double dist = cv::compareHist(lost[i]->hist, hists[j], cv::HISTCMP_BHATTACHARYYA);
        if (dist <= o_.reid_max_distance) cost[i][j] = dist;
      }
    }
    const std::vector<int> a = SolveAssignment(cost);
    for (size_t i = 0; i < lost.size(); ++i) {
      if (a[i] < 0) continue;
      Track& t = *lost[i];
      t.Init(detections[unmatched[a[i]]].box);
      Apply(t, unmatched[a[i]], detections, fd);
      t.state = TrackPhase::kTracked;
      ++stats_.refound;
    }
  }
  for (int d : unmatched) {
    if (fd.used[d]) continue;
    auto t = std::make_unique<Track>();
    t->Init(detections[d].box);
    t->score = detections[d].score;
    t->hits = 1;
    t->matched = true;
    if (camera_) t->field_m = FootOnGround(*camera_, t->box, o_.foot_offset_m);
    t->hist = TorsoHistogram(frame, detections[d].box);
    if (frame_ == 1 || o_.min_hits <= 1) {
      t->state = TrackPhase::kTracked;
      t->id = next_id_++;
      ++stats_.tracks_started;
    }
    tracks_.push_back(std::move(t));
  }
}

std::vector<TrackState> ByteTracker::Report() const {
  std::vector<TrackState> out;
  for (auto& t : tracks_) {
    if (t->state != TrackPhase::kTracked || t->id == 0) continue;
    if (!t->matched && !t->sot_box) continue;
    out.push_back({t->id, t->box, t->matched ? t->score : 0.0, t->field_m, !t->matched});
  }
  return out;
}

std::vector<TrackState> ByteTracker::Update(const std::vector<Detection>& detections,
                                            const cv::Mat& frame) {
  ++frame_;
  ++stats_.frames;
  PredictTracks(frame);
  DropExpired();
  FrameDetections fd = SortDetections(detections, frame, o_, camera_ ? &*camera_ : nullptr);
  AssociateAll(detections, fd);
  ConfirmOrMiss(frame);  // tracks not matched: single-target tracker or lost
  RefindOrStart(detections, fd, frame);
  DropExpired();
  std::vector<TrackState> out = Report();
  if (o_.sot != "none" && !frame.empty()) previous_frame_ = frame.clone();
  return out;
}

}  // namespace fv::track
