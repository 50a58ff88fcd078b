// Options, status names, the ball-centre model and the checks shared by the methods.
#include "fieldvision/recon/triangulation.h"

#include <algorithm>
#include <cmath>

#include "fieldvision/recon/triangulation_internal.h"
#include "fieldvision/util/error.h"

namespace fv::recon::detail {

double Depth(const camera::Camera& cam, const Eigen::Vector3d& p_world) {
  return (cam.cam_from_world * p_world).z();
}

double ModelRadius(const TriangulationOptions& o) {
  return o.outline_centre ? o.ball_radius_m : 0.0;
}

double Threshold(const TriangulationOptions& o, double sigma_px) {
  return std::max(o.inlier_threshold_px, o.inlier_sigmas * sigma_px);
}

void CheckObservation(const BallObservation& obs, const std::string& what) {
  FV_REQUIRE(obs.centre_px.allFinite(), "{}: centre_px is not finite", what);
  FV_REQUIRE(std::isfinite(obs.sigma_px) && obs.sigma_px > 0,
             "{}: sigma_px must be finite and > 0 (got {})", what, obs.sigma_px);
}

void CheckCamera(const std::vector<camera::Camera>& cameras, int index) {
  FV_REQUIRE(index >= 0 && index < static_cast<int>(cameras.size()),
             "triangulation: camera index {} out of range (have {} cameras)", index,
             cameras.size());
  FV_REQUIRE(cameras[index].has_pose, "triangulation: camera {} ('{}') has no pose (rvec/tvec)",
             index, cameras[index].name);
}

bool InFrontOfAll(const std::vector<camera::Camera>& cameras, const std::vector<View>& views,
                  const Eigen::Vector3d& p, double min_depth_m) {
  for (const View& v : views) {
    if (!(Depth(cameras[v.camera], p) > min_depth_m)) return false;
  }
  return true;
}

bool BelowRest(const Eigen::Vector3d& p, const TriangulationOptions& o, double sigma_z_m) {
  return o.max_below_rest_m >= 0 && p.z() < o.ball_radius_m - o.max_below_rest_m - 3 * sigma_z_m;
}

bool NoBallThere(const Eigen::Vector3d& p, const TriangulationOptions& o, double sigma_z_m) {
  return BelowRest(p, o, sigma_z_m) ||
         (!o.allowed_region.isEmpty() && !o.allowed_region.contains(p));
}

}  // namespace fv::recon::detail

namespace fv::recon {

using detail::CameraBlock;
using detail::PredictCentre;

void TriangulationOptions::Check() const {
  CheckNonNegative(ball_radius_m, "TriangulationOptions.ball_radius_m");
  FV_REQUIRE(max_iterations >= 1 && max_iterations <= 1000,
             "TriangulationOptions.max_iterations must be in [1, 1000] (got {})", max_iterations);
  CheckPositive(inlier_threshold_px, "TriangulationOptions.inlier_threshold_px");
  CheckNonNegative(inlier_sigmas, "TriangulationOptions.inlier_sigmas");
  CheckNonNegative(min_depth_m, "TriangulationOptions.min_depth_m");
  CheckInRange(min_angle_deg, 0.0, 90.0, "TriangulationOptions.min_angle_deg");
  FV_REQUIRE(max_candidates_per_camera >= 1 && max_candidates_per_camera <= 64,
             "TriangulationOptions.max_candidates_per_camera must be in [1, 64] (got {})",
             max_candidates_per_camera);
  CheckFinite(max_below_rest_m, "TriangulationOptions.max_below_rest_m");
  if (!allowed_region.isEmpty()) {
    FV_REQUIRE(allowed_region.min().allFinite() && allowed_region.max().allFinite(),
               "TriangulationOptions.allowed_region must be finite");
  }
  CheckPositive(prior_gate_m, "TriangulationOptions.prior_gate_m");
  FV_REQUIRE(prior_override_views == 0 || prior_override_views >= 2,
             "TriangulationOptions.prior_override_views must be 0 (never) or >= 2 (got {})",
             prior_override_views);
  FV_REQUIRE(max_radius_ratio == 0.0 || max_radius_ratio > 1.0,
             "TriangulationOptions.max_radius_ratio must be 0 (off) or > 1 (got {})",
             max_radius_ratio);
  FV_REQUIRE(max_larger_radius_ratio == 0.0 || max_larger_radius_ratio > 1.0,
             "TriangulationOptions.max_larger_radius_ratio must be 0 (off) or > 1 (got {})",
             max_larger_radius_ratio);
  FV_REQUIRE(score_radius_sigma >= 0.0 && std::isfinite(score_radius_sigma),
             "TriangulationOptions.score_radius_sigma must be finite and >= 0 (got {})",
             score_radius_sigma);
  FV_REQUIRE(weak_max_radius_ratio == 0.0 || weak_max_radius_ratio > 1.0,
             "TriangulationOptions.weak_max_radius_ratio must be 0 (off) or > 1 (got {})",
             weak_max_radius_ratio);
  CheckNonNegative(min_two_view_score, "TriangulationOptions.min_two_view_score");
  FV_REQUIRE(
      still_max_change >= 0.0 && still_max_change < new_min_change && new_min_change <= 1.0,
      "TriangulationOptions: still_max_change ({}) and new_min_change ({}) must satisfy 0 <= "
      "still_max_change < new_min_change <= 1",
      still_max_change, new_min_change);
  CheckNonNegative(radius_sigma_factor, "TriangulationOptions.radius_sigma_factor");
  CheckNonNegative(radius_tolerance, "TriangulationOptions.radius_tolerance");
  CheckNonNegative(radius_tolerance_px, "TriangulationOptions.radius_tolerance_px");
  FV_REQUIRE(min_views_all_weak == 0 || min_views_all_weak >= 2,
             "TriangulationOptions.min_views_all_weak must be 0 (never) or >= 2 (got {})",
             min_views_all_weak);
}

const char* ToString(TriangulationStatus status) {
  switch (status) {
    case TriangulationStatus::kOk:
      return "ok";
    case TriangulationStatus::kTooFewViews:
      return "too few views";
    case TriangulationStatus::kDegenerate:
      return "degenerate (parallel rays)";
    case TriangulationStatus::kBehindCamera:
      return "behind a camera";
    case TriangulationStatus::kNoConsistentSet:
      return "no consistent set of cameras";
  }
  return "?";
}

std::optional<Eigen::Vector2d> PredictBallCentre(const camera::Camera& camera,
                                                 const Eigen::Vector3d& point_world,
                                                 double radius_m) {
  const CameraBlock block(camera);
  Eigen::Vector2d uv;
  if (!PredictCentre(block, radius_m, point_world.data(), uv.data())) return std::nullopt;
  return uv;
}

}  // namespace fv::recon
