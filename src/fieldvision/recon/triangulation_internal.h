// Shared by the triangulation methods (triangulation_*.cc), not part of the public interface:
// the templated ball-centre projection and the checks and helpers they all use.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <ceres/rotation.h>

#include "fieldvision/camera/projection.h"
#include "fieldvision/recon/triangulation.h"

namespace fv::recon::detail {

constexpr double kRadToDeg = 180.0 / M_PI;

// The camera's parameters as plain arrays for the templated projection.
struct CameraBlock {
  std::array<double, camera::kNumIntrinsics> intrinsics;
  std::array<double, 3> rvec;
  std::array<double, 3> tvec;
  explicit CameraBlock(const camera::Camera& cam) : intrinsics(cam.IntrinsicsBlock()) {
    const Eigen::Vector3d r = cam.cam_from_world.Rvec();
    const Eigen::Vector3d& t = cam.cam_from_world.translation;
    rvec = {r.x(), r.y(), r.z()};
    tvec = {t.x(), t.y(), t.z()};
  }
};

// World point -> predicted blob centre in pixels (see the header for the outline model).
template <typename T>
bool PredictCentre(const CameraBlock& cam, double radius_m, const T* p_world, T* uv) {
  T intr[camera::kNumIntrinsics];
  for (int i = 0; i < camera::kNumIntrinsics; ++i) intr[i] = T(cam.intrinsics[i]);
  const T rvec[3] = {T(cam.rvec[0]), T(cam.rvec[1]), T(cam.rvec[2])};
  const T tvec[3] = {T(cam.tvec[0]), T(cam.tvec[1]), T(cam.tvec[2])};
  if (radius_m <= 0.0) return camera::ProjectWorldPoint(intr, rvec, tvec, p_world, uv);
  T p_cam[3];
  ceres::AngleAxisRotatePoint(rvec, p_world, p_cam);
  for (int i = 0; i < 3; ++i) p_cam[i] += tvec[i];
  if (!(p_cam[2] > T(radius_m))) return false;
  // Scaling the normalized point by Z^2 / (Z^2 - r^2) moves it to the outline's centre.
  const T q[3] = {p_cam[0] * p_cam[2], p_cam[1] * p_cam[2],
                  p_cam[2] * p_cam[2] - T(radius_m * radius_m)};
  return camera::ProjectCameraPoint(intr, q, uv);
}

double Depth(const camera::Camera& cam, const Eigen::Vector3d& p_world);
// Radius for the outline-centre model (0: observations are projections of the centre).
double ModelRadius(const TriangulationOptions& o);
// The reprojection error below which a view is consistent.
double Threshold(const TriangulationOptions& o, double sigma_px);
void CheckObservation(const BallObservation& obs, const std::string& what);
void CheckCamera(const std::vector<camera::Camera>& cameras, int index);
bool InFrontOfAll(const std::vector<camera::Camera>& cameras, const std::vector<View>& views,
                  const Eigen::Vector3d& p, double min_depth_m);
// True when the centre `p` lies lower than a resting ball's by more than max_below_rest_m plus
// three times `sigma_z_m` (the standard deviation of its height).
bool BelowRest(const Eigen::Vector3d& p, const TriangulationOptions& o, double sigma_z_m = 0.0);
// BelowRest, or outside options.allowed_region: no ball centre can be at `p`.
bool NoBallThere(const Eigen::Vector3d& p, const TriangulationOptions& o, double sigma_z_m = 0.0);

// Refines `p` (3 values, or x, y when `ground`) on the views; fills residuals, rms, covariance.
void Refine(const std::vector<camera::Camera>& cameras, const std::vector<View>& views,
            const std::vector<int>& candidate_index, bool ground, const TriangulationOptions& o,
            Eigen::Vector3d* p, TriangulationResult* result);

// All views together (triangulation_refine.cc): degeneracy check, DLT, refinement; the
// candidate index of each view is reported in the residuals.
TriangulationResult TriangulateViews(const std::vector<camera::Camera>& cameras,
                                     const std::vector<View>& views,
                                     const std::vector<int>& candidate_index,
                                     const TriangulationOptions& o);

// ---- The robust search's stages (triangulation_robust.cc)

// Per camera: the best max_candidates_per_camera candidates by score, their rays, and the cameras
// with any candidate.
struct RankedCandidates {
  std::vector<std::vector<int>> order;  // candidate indices, best first
  std::vector<std::vector<std::optional<geometry::Ray3d>>>
      rays;               // by candidate index (ranked ones)
  std::vector<int> seen;  // cameras with candidates
};
RankedCandidates RankCandidates(const std::vector<camera::Camera>& cameras,
                                const std::vector<std::vector<BallObservation>>& candidates,
                                const TriangulationOptions& o);
// The reported radius against the one that the depth of p predicts, within max_ratio either way
// (true when max_ratio is 0 or a radius is unknown).
bool RadiusConsistent(const camera::Camera& camera, const BallObservation& obs,
                      const Eigen::Vector3d& p, double ball_radius_m, double max_ratio,
                      double max_larger_ratio = 0.0);
// The candidate's score weighted by how well its radius fits the depth of p
// (TriangulationOptions::score_radius_sigma; the score itself when off or a radius is unknown).
double RadiusWeightedScore(const camera::Camera& camera, const BallObservation& obs,
                           const Eigen::Vector3d& p, const TriangulationOptions& o);
// The candidate's reprojection error at p when it is consistent with p (in front, within the
// threshold, radius checks), else -1.
double ConsistentError(const camera::Camera& camera, const BallObservation& obs,
                       const Eigen::Vector3d& p, const TriangulationOptions& o);
// For a point: the best consistent candidate of every camera (-1: none) in *pick, and the
// sigma-weighted squared error of those.
double GatherConsistent(const std::vector<camera::Camera>& cameras,
                        const std::vector<std::vector<BallObservation>>& candidates,
                        const RankedCandidates& ranked, const TriangulationOptions& o,
                        const Eigen::Vector3d& p, std::vector<int>* pick);
int CountPicked(const std::vector<int>& pick);
// A set keeps a candidate that is not weak, or is all weak but seen by min_views_all_weak
// cameras within prior_gate_m of the prior.
bool StrongEnough(const std::vector<std::vector<BallObservation>>& candidates,
                  const std::vector<int>& pick, const Eigen::Vector3d& p,
                  const TriangulationOptions& o, const Eigen::Vector3d* prior);
struct BestHypothesis {
  std::vector<int> pick;  // candidate per camera, -1: none
  int n = 0;              // cameras in the set
  double cost = 0, score = 0;
  int hypotheses = 0;                                          // two-view hypotheses scored
  std::vector<TriangulationResult::Alternative> alternatives;  // consistent hypotheses' points
};
// Every two-view hypothesis: the set with the most cameras, then the highest total score, then
// the smallest error.
BestHypothesis SearchHypotheses(const std::vector<camera::Camera>& cameras,
                                const std::vector<std::vector<BallObservation>>& candidates,
                                const RankedCandidates& ranked, const TriangulationOptions& o,
                                bool require_strong, const Eigen::Vector3d* prior);
// Refines on the set, re-gathers once with the refined point, then drops the views the refined
// point does not explain (kNoConsistentSet below two).
TriangulationResult RefineConsistentSet(const std::vector<camera::Camera>& cameras,
                                        const std::vector<std::vector<BallObservation>>& candidates,
                                        const RankedCandidates& ranked,
                                        const TriangulationOptions& o, std::vector<int> pick);

}  // namespace fv::recon::detail
