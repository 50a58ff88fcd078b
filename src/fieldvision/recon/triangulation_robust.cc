// Robust search: every two-view hypothesis over the cameras' candidates scored against all
// cameras, the largest consistent set kept and refined (exhaustive RANSAC, Fischler & Bolles
// 1981); weak candidates only where the others give no position.
#include "fieldvision/recon/triangulation.h"

#include <algorithm>
#include <numeric>
#include <optional>

#include <fmt/format.h>

#include "fieldvision/recon/triangulation_internal.h"
#include "fieldvision/util/error.h"

namespace fv {

using triangulation_detail::CheckCamera;
using triangulation_detail::CheckObservation;
using triangulation_detail::Depth;
using triangulation_detail::ModelRadius;
using triangulation_detail::Threshold;
using triangulation_detail::TriangulateViews;

namespace {

// The robust search. With require_strong, the final set must keep a candidate that is not weak
// (or have min_views_all_weak views), and there is no single-camera ground mode.
TriangulationResult RobustCore(const std::vector<Camera>& cameras,
                               const std::vector<std::vector<BallObservation>>& candidates,
                               const TriangulationOptions& o, bool require_strong,
                               const Eigen::Vector3d* prior) {
  const int num_cams = static_cast<int>(cameras.size());
  // The best candidates of each camera, by score.
  std::vector<std::vector<int>> order(num_cams);
  std::vector<std::vector<std::optional<Ray3d>>> rays(num_cams);
  std::vector<int> seen;
  for (int c = 0; c < num_cams; ++c) {
    if (candidates[c].empty()) continue;
    CheckCamera(cameras, c);
    for (size_t k = 0; k < candidates[c].size(); ++k) {
      CheckObservation(candidates[c][k], fmt::format("triangulation camera {} candidate {}", c, k));
    }
    order[c].resize(candidates[c].size());
    std::iota(order[c].begin(), order[c].end(), 0);
    std::stable_sort(order[c].begin(), order[c].end(),
                     [&](int a, int b) { return candidates[c][a].score > candidates[c][b].score; });
    if (static_cast<int>(order[c].size()) > o.max_candidates_per_camera) {
      order[c].resize(o.max_candidates_per_camera);
    }
    rays[c].resize(candidates[c].size());
    for (int k : order[c]) rays[c][k] = cameras[c].RayFromPixel(candidates[c][k].centre_px);
    seen.push_back(c);
  }
  TriangulationResult result;
  if (seen.size() < 2) {
    if (seen.size() == 1 && o.single_camera_ground && !require_strong) {
      const int c = seen[0];
      result = LocateOnGround(cameras[c], c, candidates[c][order[c][0]], o);
      if (!result.views.empty()) result.views[0].candidate = order[c][0];
      return result;
    }
    result.status = TriangulationStatus::kTooFewViews;
    return result;
  }
  // Consistency of candidate k of camera c with a point: its reprojection error, or -1.
  auto view_error = [&](int c, int k, const Eigen::Vector3d& p) -> double {
    const BallObservation& obs = candidates[c][k];
    if (!(Depth(cameras[c], p) > o.min_depth_m)) return -1;
    const auto uv = PredictBallCentre(cameras[c], p, ModelRadius(o));
    if (!uv) return -1;
    const double err = (*uv - obs.centre_px).norm();
    if (err > Threshold(o, obs.sigma_px)) return -1;
    // The reported radius against the one the depth predicts, within max_ratio either way
    // (0: no check).
    auto radius_ok = [&](double max_ratio) {
      if (max_ratio <= 0 || obs.radius_px <= 0 || o.ball_radius_m <= 0) return true;
      const Camera& cam = cameras[c];
      const double expected = o.ball_radius_m * std::sqrt(cam.fx * cam.fy) / Depth(cam, p);
      const double ratio = obs.radius_px / expected;
      return ratio <= max_ratio && ratio >= 1.0 / max_ratio;
    };
    if (!radius_ok(o.max_radius_ratio)) return -1;
    if (obs.weak && !radius_ok(o.weak_max_radius_ratio)) return -1;
    return err;
  };
  // For a point: the best consistent candidate of every camera and the weighted squared error.
  auto gather = [&](const Eigen::Vector3d& p, std::vector<int>* pick) {
    pick->assign(num_cams, -1);
    double cost = 0;
    for (int c : seen) {
      double best = -1;
      for (int k : order[c]) {
        const double e = view_error(c, k, p);
        if (e >= 0 && (best < 0 || e < best)) {
          best = e;
          (*pick)[c] = k;
        }
      }
      if (best >= 0) {
        const double s = candidates[c][(*pick)[c]].sigma_px;
        cost += best * best / (s * s);
      }
    }
    return cost;
  };
  auto count = [](const std::vector<int>& pick) {
    return static_cast<int>(std::count_if(pick.begin(), pick.end(), [](int k) { return k >= 0; }));
  };
  // With require_strong: a set keeps a candidate that is not weak, or is all weak but seen by
  // min_views_all_weak cameras near the prior.
  auto weak_set_ok = [&](const std::vector<int>& pick, int n, const Eigen::Vector3d& p) {
    for (int c = 0; c < num_cams; ++c) {
      if (pick[c] >= 0 && !candidates[c][pick[c]].weak) return true;
    }
    return o.min_views_all_weak > 0 && n >= o.min_views_all_weak && prior != nullptr &&
           (p - *prior).norm() <= o.prior_gate_m;
  };
  std::vector<int> best_pick;
  int best_n = 0;
  double best_cost = 0, best_score = 0;
  int hypotheses = 0;
  std::vector<int> pick;
  for (size_t ia = 0; ia < seen.size(); ++ia) {
    for (size_t ib = ia + 1; ib < seen.size(); ++ib) {
      const int ca = seen[ia], cb = seen[ib];
      for (int ka : order[ca]) {
        if (!rays[ca][ka]) continue;
        for (int kb : order[cb]) {
          if (!rays[cb][kb]) continue;
          if (require_strong && o.min_views_all_weak == 0 && candidates[ca][ka].weak &&
              candidates[cb][kb].weak) {
            continue;
          }
          const RayPairResult rp =
              ClosestPointOfRays(*rays[ca][ka], *rays[cb][kb], o.min_angle_deg);
          if (!rp.ok()) continue;
          if (o.max_below_ground_m >= 0 && rp.midpoint.z() < -o.max_below_ground_m) continue;
          ++hypotheses;
          const double cost = gather(rp.midpoint, &pick);
          if (pick[ca] != ka || pick[cb] != kb) continue;  // the pair itself must agree
          const int n = count(pick);
          if (require_strong && !weak_set_ok(pick, n, rp.midpoint)) continue;
          double score = 0;
          for (int c : seen) {
            if (pick[c] >= 0) score += candidates[c][pick[c]].score;
          }
          // More cameras first, then higher total detector score, then smaller error.
          const bool better =
              n > best_n || (n == best_n && (score > best_score + 1e-9 ||
                                             (score > best_score - 1e-9 && cost < best_cost)));
          if (better) {
            best_n = n;
            best_cost = cost;
            best_score = score;
            best_pick = pick;
          }
        }
      }
    }
  }
  if (best_n < 2) {
    result.status = TriangulationStatus::kNoConsistentSet;
    result.hypotheses = hypotheses;
    return result;
  }
  // Refine on the consistent set, re-gather once with the refined point, then drop views
  // that the refined point does not explain.
  auto solve = [&](const std::vector<int>& p) {
    std::vector<View> views;
    std::vector<int> cand;
    for (int c = 0; c < num_cams; ++c) {
      if (p[c] >= 0) {
        views.push_back({c, candidates[c][p[c]]});
        cand.push_back(p[c]);
      }
    }
    return TriangulateViews(cameras, views, cand, o);
  };
  result = solve(best_pick);
  if (result.ok()) {
    std::vector<int> again;
    gather(result.point_world, &again);
    if (count(again) >= best_n && again != best_pick) {
      TriangulationResult r2 = solve(again);
      if (r2.ok()) {
        result = r2;
        best_pick = again;
      }
    }
  }
  while (result.ok()) {
    const auto worst = std::max_element(
        result.views.begin(), result.views.end(),
        [&](const ViewResidual& a, const ViewResidual& b) {
          return a.err_px / Threshold(o, candidates[a.camera][a.candidate].sigma_px) <
                 b.err_px / Threshold(o, candidates[b.camera][b.candidate].sigma_px);
        });
    if (worst->err_px <= Threshold(o, candidates[worst->camera][worst->candidate].sigma_px)) break;
    if (result.views.size() <= 2) {
      result.status = TriangulationStatus::kNoConsistentSet;
      break;
    }
    best_pick[worst->camera] = -1;
    result = solve(best_pick);
  }
  if (result.ok()) {
    for (const ViewResidual& v : result.views) {
      result.weak_views += candidates[v.camera][v.candidate].weak;
    }
    std::vector<int> used(num_cams, -1);
    for (const ViewResidual& v : result.views) used[v.camera] = v.candidate;
    if (require_strong && !weak_set_ok(used, result.num_views(), result.point_world)) {
      result.status = TriangulationStatus::kNoConsistentSet;
    }
  }
  result.hypotheses = hypotheses;
  return result;
}

}  // namespace

TriangulationResult TriangulateRobust(const std::vector<Camera>& cameras,
                                      const std::vector<std::vector<BallObservation>>& candidates,
                                      const TriangulationOptions& o, const Eigen::Vector3d* prior) {
  o.Check();
  FV_REQUIRE(candidates.size() == cameras.size(),
             "TriangulateRobust: {} candidate lists for {} cameras", candidates.size(),
             cameras.size());
  FV_REQUIRE(prior == nullptr || prior->allFinite(), "TriangulateRobust: the prior is not finite");
  bool any_weak = false;
  for (const auto& list : candidates) {
    for (const BallObservation& obs : list) any_weak = any_weak || obs.weak;
  }
  if (!any_weak) return RobustCore(cameras, candidates, o, false, nullptr);
  // The candidates that are not weak first, alone: a weak one never moves what they give.
  std::vector<std::vector<BallObservation>> strong(candidates.size());
  std::vector<std::vector<int>> index(candidates.size());
  for (size_t c = 0; c < candidates.size(); ++c) {
    for (size_t k = 0; k < candidates[c].size(); ++k) {
      if (candidates[c][k].weak) continue;
      strong[c].push_back(candidates[c][k]);
      index[c].push_back(static_cast<int>(k));
    }
  }
  TriangulationResult result = RobustCore(cameras, strong, o, false, nullptr);
  for (ViewResidual& v : result.views) {
    if (v.candidate >= 0) v.candidate = index[v.camera][v.candidate];
  }
  if ((result.ok() && !result.on_ground) || !o.use_weak) return result;
  TriangulationResult with_weak = RobustCore(cameras, candidates, o, true, prior);
  with_weak.hypotheses += result.hypotheses;
  return with_weak.ok() ? with_weak : result;
}

}  // namespace fv
