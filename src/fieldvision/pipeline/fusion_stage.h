// The fusion stage of the ball pipeline: a synchronised multi-camera frame (frame_sync.h) in, a
// robustly triangulated ball position out (recon/triangulation.h), with the last positions as
// the prior of the next frame (BallPredictor; none from a track that stands still in the air,
// which no ball does) and per-camera counts for the summary. The same
// stage serves the in-process pipeline (ball_pipeline.h) and the fusion node (net/fuse.h).
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/pipeline/frame_sync.h"
#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/triangulation.h"

namespace fv::pipeline {

// The fused result of one synchronised frame.
struct BallFrame {
  long long frame = 0;
  double time_s = 0.0;
  int cameras_present = 0;     // cameras with a message for this frame
  int cameras_with_blobs = 0;  // of those, cameras with at least one candidate
  recon::TriangulationResult result;
};

// The fusion of one synchronised frame (what the fusion stage does per frame).
BallFrame FuseFrame(const std::vector<camera::Camera>& cameras, const SyncedFrame& frame,
                    const recon::TriangulationOptions& options,
                    const Eigen::Vector3d* prior = nullptr);

// The trajectory sample of a frame with a position (its point, cameras and error).
recon::BallSample BallSampleOf(const BallFrame& frame);

// The ball's expected position from the last two positions (constant velocity), only while they
// form a track: at most max_gap frames apart, the newest at most max_gap frames old, and at most
// max_step_m apart per frame (independent placements, as in a static scene or a jump to
// another object, are no track). The prior gates the next frame's hypotheses (recon::
// TriangulationOptions::gate_by_prior). max_gap 12 (0.2 s at 60 fps) keeps a ball lost for a
// moment over ball-coloured boards gated against a 2-camera ghost elsewhere (low-sun-kick render:
// 5 frames -> 12: 0.5 m off 8 -> 1, found 182 -> 177 of 192).
class BallPredictor {
 public:
  explicit BallPredictor(int max_gap = 12, double max_step_m = 1.5)
      : max_gap_(max_gap), max_step_m_(max_step_m) {}
  void Add(long long frame, const Eigen::Vector3d& point_world);
  std::optional<Eigen::Vector3d> Predict(long long frame) const;
  // The track's speed in metres per frame where Predict gives a position, else nullopt.
  std::optional<double> StepPerFrame(long long frame) const;

 private:
  int max_gap_;
  double max_step_m_;
  int count_ = 0;
  long long frame_[2] = {0, 0};  // [0] newest
  Eigen::Vector3d point_[2];
};

// Ball-coloured things that stand still above the ground (a seat in the stands, a sign, seen
// as a ball by two cameras whose rays meet there): a ball cannot hover, so an airborne position
// (higher than a resting ball by airborne_m and three standard deviations of its height) that
// repeats one point (within radius_m or three standard deviations of the two positions' distance)
// at least min_count times over at least min_span_s, all those heights within half of g T^2 / 8
// (T = min_span_s), is not the ball: a free ball's heights span at least g T^2 / 8 over any T
// seconds (11 cm in 0.3 s, about its apex), however slowly it moves across or often it comes
// back (juggled). A ghost's horizontal position jitters with its blobs' shapes, hence 25 cm.
struct HoverFilterOptions {
  double radius_m = 0.25;    // the same point: closer than this
  double min_span_s = 0.3;   // seen there over at least this long
  int min_count = 3;         // this many times, the position tested included
  double airborne_m = 0.05;  // height above a resting ball's centre that is airborne
  double memory_s = 60.0;    // airborne positions are remembered this long
  // Throws fv::Error naming the bad field.
  void Check() const;
};

class HoverFilter {
 public:
  explicit HoverFilter(const HoverFilterOptions& options = {}, double ball_radius_m = 0.11);
  // Whether a 3D result lies above a resting ball by more than airborne_m and 3 sigma.
  bool Airborne(const recon::TriangulationResult& result) const;
  bool Airborne(const Eigen::Vector3d& point_world, double sigma_z_m) const;
  // Remembers an airborne position (a consistent hypothesis that was not chosen).
  void Record(double time_s, const Eigen::Vector3d& point_world, double sigma_m);
  // Remembers an airborne position (sigma_m: its 3D RMS uncertainty); true when it repeats a
  // point that hovers (seen there in min_count frames, this one included). Positions remembered
  // at other times count, later ones too (RememberAfter).
  bool RecordAndTest(double time_s, const Eigen::Vector3d& point_world, double sigma_m = 0.0);
  // Adds what `other` remembers after `after_time_s` (a first pass over the same clip, running
  // ahead): a second pass then knows each still point from its future too and drops a ghost from
  // its first frame on. Returns the latest time added (after_time_s when none).
  double RememberAfter(const HoverFilter& other, double after_time_s);

 private:
  HoverFilterOptions options_;
  double ball_radius_m_;
  struct Seen {
    double time_s;
    Eigen::Vector3d point_world;
    double sigma_m;
  };
  std::deque<Seen> seen_;  // oldest first
};

struct FusionStats {
  long long frames = 0;                          // synchronised frames
  long long frames_with_position = 0;            // 3D (or ground) positions
  long long ground_positions = 0;                // single-camera ground positions among them
  long long weak_positions = 0;                  // positions completed with weak candidates
  long long hovering_dropped = 0;                // airborne points that stand still (HoverFilter)
  long long frames_few_blobs = 0;                // no position: fewer than 2 cameras had candidates
  long long frames_inconsistent = 0;             // no position although >= 2 cameras had candidates
  double sum_err_px = 0.0;                       // sum of the positions' RMS reprojection errors
  std::vector<long long> used_per_camera;        // positions each camera contributed to
  std::vector<long long> candidates_per_camera;  // accepted candidates each camera reported
};

class FusionStage {
 public:
  // Throws fv::Error when there is no camera or the options are bad.
  FusionStage(std::vector<camera::Camera> cameras, const recon::TriangulationOptions& options);
  BallFrame Fuse(const SyncedFrame& frame);
  // A second pass over a clip: the airborne positions `first_pass` saw after `after_time_s`, later
  // ones too, count for the hover test (HoverFilter::RememberAfter); returns the latest time added.
  double RememberHovering(const FusionStage& first_pass, double after_time_s) {
    return hover_.RememberAfter(first_pass.hover_, after_time_s);
  }
  const FusionStats& stats() const { return stats_; }
  const std::vector<camera::Camera>& cameras() const { return cameras_; }

 private:
  std::vector<camera::Camera> cameras_;
  recon::TriangulationOptions options_;
  BallPredictor predictor_;
  HoverFilter hover_;
  FusionStats stats_;
};

}  // namespace fv::pipeline
