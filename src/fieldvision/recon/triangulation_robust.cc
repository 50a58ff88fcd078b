// Robust search: every two-view hypothesis over the cameras' candidates scored against all
// cameras, the largest consistent set kept and refined (exhaustive RANSAC, Fischler & Bolles
// 1981); weak candidates only where the others give no position.
#include "fieldvision/recon/triangulation.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include <fmt/format.h>

#include "fieldvision/camera/sphere_image.h"
#include "fieldvision/recon/triangulation_internal.h"
#include "fieldvision/util/error.h"

namespace fv::recon::detail {

RankedCandidates RankCandidates(const std::vector<camera::Camera>& cameras,
                                const std::vector<std::vector<BallObservation>>& candidates,
                                const TriangulationOptions& o) {
  const int num_cams = static_cast<int>(cameras.size());
  RankedCandidates r;
  r.order.resize(num_cams);
  r.rays.resize(num_cams);
  for (int c = 0; c < num_cams; ++c) {
    if (candidates[c].empty()) continue;
    CheckCamera(cameras, c);
    for (size_t k = 0; k < candidates[c].size(); ++k) {
      CheckObservation(candidates[c][k], fmt::format("triangulation camera {} candidate {}", c, k));
    }
    std::vector<int>& order = r.order[c];
    order.resize(candidates[c].size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return candidates[c][a].score > candidates[c][b].score; });
    if (static_cast<int>(order.size()) > o.max_candidates_per_camera) {
      order.resize(o.max_candidates_per_camera);
    }
    r.rays[c].resize(candidates[c].size());
    for (int k : order) r.rays[c][k] = cameras[c].RayFromPixel(candidates[c][k].centre_px);
    r.seen.push_back(c);
  }
  return r;
}

bool RadiusConsistent(const camera::Camera& camera, const BallObservation& obs,
                      const Eigen::Vector3d& p, double ball_radius_m, double max_ratio,
                      double max_larger_ratio) {
  if ((max_ratio <= 0 && max_larger_ratio <= 0) || obs.radius_px <= 0 || ball_radius_m <= 0) {
    return true;
  }
  const auto expected = camera::SphereRadiusPx(camera, p, ball_radius_m);
  if (!expected || !(*expected > 0)) return false;  // not in front of the camera
  const double ratio = obs.radius_px / *expected;
  if (max_larger_ratio > 0 && ratio > max_larger_ratio) return false;
  return max_ratio <= 0 || (ratio <= max_ratio && ratio >= 1.0 / max_ratio);
}

double RadiusWeightedScore(const camera::Camera& camera, const BallObservation& obs,
                           const Eigen::Vector3d& p, const TriangulationOptions& o) {
  if (o.score_radius_sigma <= 0 || obs.radius_px <= 0 || o.ball_radius_m <= 0) return obs.score;
  // Not in front of the camera (no projection): the score alone.
  const auto expected = camera::SphereRadiusPx(camera, p, o.ball_radius_m);
  if (!expected || !(*expected > 0) || !std::isfinite(*expected)) return obs.score;
  const double z = std::log(obs.radius_px / *expected) / o.score_radius_sigma;
  return obs.score * std::exp(-0.5 * z * z);
}

double ConsistentError(const camera::Camera& camera, const BallObservation& obs,
                       const Eigen::Vector3d& p, const TriangulationOptions& o) {
  if (!(Depth(camera, p) > o.min_depth_m)) return -1;
  const auto uv = PredictBallCentre(camera, p, ModelRadius(o));
  if (!uv) return -1;
  const double err = (*uv - obs.centre_px).norm();
  if (err > Threshold(o, obs.sigma_px)) return -1;
  if (!RadiusConsistent(camera, obs, p, o.ball_radius_m, o.max_radius_ratio,
                        o.max_larger_radius_ratio)) {
    return -1;
  }
  // The larger-radius bound was applied above.
  if (obs.weak && !RadiusConsistent(camera, obs, p, o.ball_radius_m, o.weak_max_radius_ratio)) {
    return -1;
  }
  return err;
}

double GatherConsistent(const std::vector<camera::Camera>& cameras,
                        const std::vector<std::vector<BallObservation>>& candidates,
                        const RankedCandidates& ranked, const TriangulationOptions& o,
                        const Eigen::Vector3d& p, std::vector<int>* pick) {
  pick->assign(cameras.size(), -1);
  double cost = 0;
  for (int c : ranked.seen) {
    double best = -1;
    for (int k : ranked.order[c]) {
      const double e = ConsistentError(cameras[c], candidates[c][k], p, o);
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
}

int CountPicked(const std::vector<int>& pick) {
  return static_cast<int>(std::count_if(pick.begin(), pick.end(), [](int k) { return k >= 0; }));
}

bool StrongEnough(const std::vector<std::vector<BallObservation>>& candidates,
                  const std::vector<int>& pick, const Eigen::Vector3d& p,
                  const TriangulationOptions& o, const Eigen::Vector3d* prior) {
  for (size_t c = 0; c < pick.size(); ++c) {
    if (pick[c] >= 0 && !candidates[c][pick[c]].weak) return true;
  }
  return o.min_views_all_weak > 0 && CountPicked(pick) >= o.min_views_all_weak &&
         prior != nullptr && (p - *prior).norm() <= o.prior_gate_m;
}

// A hypothesis whose views lie within three standard deviations on average is consistent (its
// point is kept among the alternatives, at most kMaxAlternatives of them).
constexpr double kConsistentChi2PerView = 9.0;
constexpr size_t kMaxAlternatives = 64;

// 1-sigma size of the midpoint of two rays: each ray's lateral uncertainty at its depth
// (depth * sigma_px / focal length), over the sine of the angle between the rays.
double PairSigma(const camera::Camera& cam_a, const BallObservation& a, const camera::Camera& cam_b,
                 const BallObservation& b, const RayPairResult& rp) {
  const double lateral_a = std::abs(rp.s_a) * a.sigma_px / std::sqrt(cam_a.fx * cam_a.fy);
  const double lateral_b = std::abs(rp.s_b) * b.sigma_px / std::sqrt(cam_b.fx * cam_b.fy);
  const double sin_angle = std::max(std::sin(rp.angle_deg * M_PI / 180.0), 1e-3);
  return std::hypot(lateral_a, lateral_b) / sin_angle;
}

namespace {

// One view of a thing that came into view and one of a thing that was always there
// (TriangulationOptions::still_max_change).
bool NewAndStill(const BallObservation& a, const BallObservation& b,
                 const TriangulationOptions& o) {
  if (o.still_max_change <= 0 || a.background_change < 0 || b.background_change < 0) return false;
  const auto still = [&](const BallObservation& v) {
    return v.background_change <= o.still_max_change;
  };
  const auto fresh = [&](const BallObservation& v) {
    return v.background_change >= o.new_min_change;
  };
  return (still(a) && fresh(b)) || (fresh(a) && still(b));
}

// Keeps the set (n cameras, cost, total detector score) in `best` when it is better: more cameras
// first, then a higher total score, then a smaller error.
void KeepBetter(int n, double cost, double score, const std::vector<int>& pick,
                BestHypothesis* best) {
  const bool better =
      n > best->n || (n == best->n && (score > best->score + 1e-9 ||
                                       (score > best->score - 1e-9 && cost < best->cost)));
  if (better) {
    best->n = n;
    best->cost = cost;
    best->score = score;
    best->pick = pick;
  }
}

}  // namespace

BestHypothesis SearchHypotheses(const std::vector<camera::Camera>& cameras,
                                const std::vector<std::vector<BallObservation>>& candidates,
                                const RankedCandidates& ranked, const TriangulationOptions& o,
                                bool require_strong, const Eigen::Vector3d* prior) {
  BestHypothesis best, far;
  std::vector<int> pick;
  const std::vector<int>& seen = ranked.seen;
  for (size_t ia = 0; ia < seen.size(); ++ia) {
    for (size_t ib = ia + 1; ib < seen.size(); ++ib) {
      const int ca = seen[ia], cb = seen[ib];
      for (int ka : ranked.order[ca]) {
        if (!ranked.rays[ca][ka]) continue;
        for (int kb : ranked.order[cb]) {
          if (!ranked.rays[cb][kb]) continue;
          if (require_strong && o.min_views_all_weak == 0 && candidates[ca][ka].weak &&
              candidates[cb][kb].weak) {
            continue;
          }
          const RayPairResult rp =
              ClosestPointOfRays(*ranked.rays[ca][ka], *ranked.rays[cb][kb], o.min_angle_deg);
          if (!rp.ok()) continue;
          if (NoBallThere(rp.midpoint, o)) continue;
          // The prior decides where the ball may be, but every consistent set is reported.
          const bool far_from_prior =
              prior == nullptr || (rp.midpoint - *prior).norm() > o.prior_gate_m;
          const bool gated = o.gate_by_prior && prior != nullptr && far_from_prior;
          if (!gated) ++best.hypotheses;
          const double cost = GatherConsistent(cameras, candidates, ranked, o, rp.midpoint, &pick);
          if (pick[ca] != ka || pick[cb] != kb) continue;  // the pair itself must agree
          const int n = CountPicked(pick);
          if (require_strong && !StrongEnough(candidates, pick, rp.midpoint, o, prior)) continue;
          if (cost <= kConsistentChi2PerView * n && best.alternatives.size() < kMaxAlternatives) {
            best.alternatives.push_back(
                {rp.midpoint,
                 PairSigma(cameras[ca], candidates[ca][ka], cameras[cb], candidates[cb][kb], rp)});
          }
          // Far from where the ball is expected: only a set of prior_override_views cameras,
          // and only when nothing lies near the prior (below).
          if (gated && (o.prior_override_views == 0 || n < o.prior_override_views)) continue;
          double score = 0;
          for (int c : seen) {
            if (pick[c] < 0) continue;
            score += RadiusWeightedScore(cameras[c], candidates[c][pick[c]], rp.midpoint, o);
          }
          // Two faint things far from where the ball is expected: no ball.
          if (n == 2 && score < o.min_two_view_score && far_from_prior) continue;
          if (n == 2 && NewAndStill(candidates[ca][ka], candidates[cb][kb], o)) continue;
          KeepBetter(n, cost, score, pick, gated ? &far : &best);
        }
      }
    }
  }
  if (best.n < 2 && far.n >= 2) {  // a new place that many cameras agree on: the ball moved
    best.n = far.n;
    best.cost = far.cost;
    best.score = far.score;
    best.pick = far.pick;
  }
  return best;
}

TriangulationResult RefineConsistentSet(const std::vector<camera::Camera>& cameras,
                                        const std::vector<std::vector<BallObservation>>& candidates,
                                        const RankedCandidates& ranked,
                                        const TriangulationOptions& o, std::vector<int> pick) {
  const int n = CountPicked(pick);
  auto solve = [&](const std::vector<int>& p) {
    std::vector<View> views;
    std::vector<int> cand;
    for (size_t c = 0; c < p.size(); ++c) {
      if (p[c] >= 0) {
        views.push_back({static_cast<int>(c), candidates[c][p[c]]});
        cand.push_back(p[c]);
      }
    }
    return TriangulateViews(cameras, views, cand, o);
  };
  TriangulationResult result = solve(pick);
  if (result.ok()) {
    std::vector<int> again;
    GatherConsistent(cameras, candidates, ranked, o, result.point_world, &again);
    if (CountPicked(again) >= n && again != pick) {
      TriangulationResult r2 = solve(again);
      if (r2.ok()) {
        result = r2;
        pick = again;
      }
    }
  }
  auto ratio = [&](const ViewResidual& v) {
    return v.err_px / Threshold(o, candidates[v.camera][v.candidate].sigma_px);
  };
  while (result.ok()) {
    const auto worst = std::max_element(
        result.views.begin(), result.views.end(),
        [&](const ViewResidual& a, const ViewResidual& b) { return ratio(a) < ratio(b); });
    if (worst->err_px <= Threshold(o, candidates[worst->camera][worst->candidate].sigma_px)) break;
    if (result.views.size() <= 2) {
      result.status = TriangulationStatus::kNoConsistentSet;
      break;
    }
    pick[worst->camera] = -1;
    result = solve(pick);
  }
  return result;
}

}  // namespace fv::recon::detail

namespace fv::recon {
namespace {

using detail::BestHypothesis;
using detail::NoBallThere;
using detail::RankCandidates;
using detail::RankedCandidates;
using detail::RefineConsistentSet;
using detail::SearchHypotheses;
using detail::StrongEnough;

// The robust search. With require_strong, the final set must keep a candidate that is not weak
// (or have min_views_all_weak views), and there is no single-camera ground mode.
TriangulationResult RobustCore(const std::vector<camera::Camera>& cameras,
                               const std::vector<std::vector<BallObservation>>& candidates,
                               const TriangulationOptions& o, bool require_strong,
                               const Eigen::Vector3d* prior) {
  const RankedCandidates ranked = RankCandidates(cameras, candidates, o);
  TriangulationResult result;
  if (ranked.seen.size() < 2) {
    if (ranked.seen.size() == 1 && o.single_camera_ground && !require_strong) {
      const int c = ranked.seen[0];
      const int k = ranked.order[c][0];
      result = LocateOnGround(cameras[c], c, candidates[c][k], o);
      if (!result.views.empty()) result.views[0].candidate = k;
      return result;
    }
    result.status = TriangulationStatus::kTooFewViews;
    return result;
  }
  // A set whose refined point lies below a resting ball (a low orange object that the cameras
  // agree on) or outside the allowed region is dropped and the search runs again without its
  // candidates, a few times at most.
  constexpr int kMaxSearches = 3;
  RankedCandidates search = ranked;
  int hypotheses = 0;
  std::vector<TriangulationResult::Alternative> alternatives;
  for (int attempt = 0; attempt < kMaxSearches; ++attempt) {
    const BestHypothesis best =
        SearchHypotheses(cameras, candidates, search, o, require_strong, prior);
    hypotheses += best.hypotheses;
    alternatives.insert(alternatives.end(), best.alternatives.begin(), best.alternatives.end());
    if (best.n < 2) {
      result = TriangulationResult();
      result.status = TriangulationStatus::kNoConsistentSet;
      break;
    }
    result = RefineConsistentSet(cameras, candidates, search, o, best.pick);
    if (!result.ok()) break;
    std::vector<int> used(cameras.size(), -1);
    for (const ViewResidual& v : result.views) {
      result.weak_views += candidates[v.camera][v.candidate].weak;
      used[v.camera] = v.candidate;
    }
    if (require_strong && !StrongEnough(candidates, used, result.point_world, o, prior)) {
      result.status = TriangulationStatus::kNoConsistentSet;
      break;
    }
    const double sigma_z_m = std::sqrt(std::max(result.covariance(2, 2), 0.0));
    if (!NoBallThere(result.point_world, o, sigma_z_m)) break;
    result.status = TriangulationStatus::kNoConsistentSet;
    for (size_t c = 0; c < used.size(); ++c) {
      if (used[c] < 0) continue;
      std::vector<int>& order = search.order[c];
      order.erase(std::remove(order.begin(), order.end(), used[c]), order.end());
    }
  }
  result.hypotheses = hypotheses;
  result.alternatives = std::move(alternatives);
  return result;
}

}  // namespace

TriangulationResult TriangulateRobust(const std::vector<camera::Camera>& cameras,
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
  if (!any_weak) return RobustCore(cameras, candidates, o, false, prior);
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
  TriangulationResult result = RobustCore(cameras, strong, o, false, prior);
  for (ViewResidual& v : result.views) {
    if (v.candidate >= 0) v.candidate = index[v.camera][v.candidate];
  }
  if ((result.ok() && !result.on_ground) || !o.use_weak) return result;
  TriangulationResult with_weak = RobustCore(cameras, candidates, o, true, prior);
  with_weak.hypotheses += result.hypotheses;
  if (!with_weak.ok()) return result;
  // The strong candidates' consistent points are the reliable ones (a weak one never moves them).
  with_weak.alternatives = std::move(result.alternatives);
  return with_weak;
}

}  // namespace fv::recon
