#include "fieldvision/recon/triangulation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numeric>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/Dense>

#include "fieldvision/camera/projection.h"
#include "fieldvision/util/error.h"

namespace fv {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// The camera's parameters as plain arrays for the templated projection.
struct CameraBlock {
  std::array<double, kNumIntrinsics> intrinsics;
  std::array<double, 3> rvec;
  std::array<double, 3> tvec;
  explicit CameraBlock(const Camera& cam) : intrinsics(cam.IntrinsicsBlock()) {
    const Eigen::Vector3d r = cam.cam_from_world.Rvec();
    const Eigen::Vector3d& t = cam.cam_from_world.translation;
    rvec = {r.x(), r.y(), r.z()};
    tvec = {t.x(), t.y(), t.z()};
  }
};

// World point -> predicted blob centre in pixels (see the header for the outline model).
template <typename T>
bool PredictCentre(const CameraBlock& cam, double radius_m, const T* p_world, T* uv) {
  T intr[kNumIntrinsics];
  for (int i = 0; i < kNumIntrinsics; ++i) intr[i] = T(cam.intrinsics[i]);
  const T rvec[3] = {T(cam.rvec[0]), T(cam.rvec[1]), T(cam.rvec[2])};
  const T tvec[3] = {T(cam.tvec[0]), T(cam.tvec[1]), T(cam.tvec[2])};
  if (radius_m <= 0.0) return ProjectWorldPoint(intr, rvec, tvec, p_world, uv);
  T p_cam[3];
  ceres::AngleAxisRotatePoint(rvec, p_world, p_cam);
  for (int i = 0; i < 3; ++i) p_cam[i] += tvec[i];
  if (!(p_cam[2] > T(radius_m))) return false;
  // Scaling the normalized point by Z^2 / (Z^2 - r^2) moves it to the outline's centre.
  const T q[3] = {p_cam[0] * p_cam[2], p_cam[1] * p_cam[2],
                  p_cam[2] * p_cam[2] - T(radius_m * radius_m)};
  return ProjectCameraPoint(intr, q, uv);
}

// Weighted reprojection residual of one view; `Ground` optimises x, y with z fixed.
template <bool Ground>
struct ReprojectionCost {
  ReprojectionCost(const CameraBlock& cam, const Eigen::Vector2d& obs, double sigma_px,
                   double radius_m, double z_m)
      : cam(cam), obs(obs), inv_sigma(1.0 / sigma_px), radius_m(radius_m), z_m(z_m) {}
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    const T p_world[3] = {p[0], p[1], Ground ? T(z_m) : p[2]};
    T uv[2];
    if (!PredictCentre(cam, radius_m, p_world, uv)) return false;
    residual[0] = (uv[0] - T(obs.x())) * T(inv_sigma);
    residual[1] = (uv[1] - T(obs.y())) * T(inv_sigma);
    return true;
  }
  CameraBlock cam;
  Eigen::Vector2d obs;
  double inv_sigma, radius_m, z_m;
};

double Depth(const Camera& cam, const Eigen::Vector3d& p_world) {
  return (cam.cam_from_world * p_world).z();
}

// Radius for the outline-centre model (0: observations are projections of the centre).
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

void CheckCamera(const std::vector<Camera>& cameras, int index) {
  FV_REQUIRE(index >= 0 && index < static_cast<int>(cameras.size()),
             "triangulation: camera index {} out of range (have {} cameras)", index,
             cameras.size());
  FV_REQUIRE(cameras[index].has_pose, "triangulation: camera {} ('{}') has no pose (rvec/tvec)",
             index, cameras[index].name);
}

// Refines `p` (3 values, or x, y when `ground`) on the views; fills residuals, rms, covariance.
void Refine(const std::vector<Camera>& cameras, const std::vector<View>& views,
            const std::vector<int>& candidate_index, bool ground, const TriangulationOptions& o,
            Eigen::Vector3d* p, TriangulationResult* result) {
  double x[3] = {p->x(), p->y(), p->z()};
  ceres::Problem problem;
  std::vector<CameraBlock> blocks;
  blocks.reserve(views.size());
  for (const View& v : views) {
    blocks.emplace_back(cameras[v.camera]);
    if (ground) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ReprojectionCost<true>, 2, 2>(
              new ReprojectionCost<true>(blocks.back(), v.observation.centre_px,
                                         v.observation.sigma_px, ModelRadius(o), x[2])),
          nullptr, x);
    } else {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ReprojectionCost<false>, 2, 3>(
              new ReprojectionCost<false>(blocks.back(), v.observation.centre_px,
                                          v.observation.sigma_px, ModelRadius(o), 0.0)),
          nullptr, x);
    }
  }
  result->iterations = 0;
  if (o.refine) {
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = o.max_iterations;
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    so.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    result->iterations = static_cast<int>(summary.iterations.size());
    if (summary.IsSolutionUsable()) *p = Eigen::Vector3d(x[0], x[1], x[2]);
  }
  x[0] = p->x();
  x[1] = p->y();
  x[2] = p->z();
  // Weighted residuals and Jacobian at the solution.
  ceres::CRSMatrix jac;
  std::vector<double> weighted;
  double cost = 0;
  const bool evaluated =
      problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, &weighted, nullptr, &jac);
  const int n = ground ? 2 : 3;
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(jac.num_rows, n);
  if (evaluated) {
    for (int r = 0; r < jac.num_rows; ++r) {
      for (int k = jac.rows[r]; k < jac.rows[r + 1]; ++k) j(r, jac.cols[k]) = jac.values[k];
    }
  }
  result->covariance.setZero();
  if (evaluated) {
    const Eigen::MatrixXd jtj = j.transpose() * j;
    Eigen::FullPivLU<Eigen::MatrixXd> lu(jtj);
    if (lu.isInvertible()) result->covariance.topLeftCorner(n, n) = lu.inverse();
  }
  result->views.clear();
  double sum2 = 0;
  for (size_t i = 0; i < views.size(); ++i) {
    const View& v = views[i];
    ViewResidual vr;
    vr.camera = v.camera;
    vr.candidate = candidate_index.empty() ? 0 : candidate_index[i];
    if (evaluated && weighted.size() >= 2 * (i + 1)) {
      vr.residual_px =
          Eigen::Vector2d(weighted[2 * i], weighted[2 * i + 1]) * v.observation.sigma_px;
    } else if (auto uv = PredictBallCentre(cameras[v.camera], *p, ModelRadius(o))) {
      vr.residual_px = *uv - v.observation.centre_px;
    } else {
      vr.residual_px = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    }
    vr.err_px = vr.residual_px.norm();
    sum2 += vr.err_px * vr.err_px;
    result->views.push_back(vr);
  }
  std::sort(result->views.begin(), result->views.end(),
            [](const ViewResidual& a, const ViewResidual& b) { return a.camera < b.camera; });
  result->rms_px = views.empty() ? 0.0 : std::sqrt(sum2 / views.size());
  result->point_world = *p;
}

bool InFrontOfAll(const std::vector<Camera>& cameras, const std::vector<View>& views,
                  const Eigen::Vector3d& p, double min_depth_m) {
  for (const View& v : views) {
    if (!(Depth(cameras[v.camera], p) > min_depth_m)) return false;
  }
  return true;
}

TriangulationResult TriangulateViews(const std::vector<Camera>& cameras,
                                     const std::vector<View>& views,
                                     const std::vector<int>& candidate_index,
                                     const TriangulationOptions& o) {
  TriangulationResult result;
  if (views.size() < 2) {
    result.status = TriangulationStatus::kTooFewViews;
    return result;
  }
  // Degenerate when every pair of rays is (nearly) parallel.
  std::vector<Eigen::Vector3d> dirs;
  for (const View& v : views) {
    auto ray = cameras[v.camera].RayFromPixel(v.observation.centre_px);
    if (!ray) {
      result.status = TriangulationStatus::kDegenerate;
      return result;
    }
    dirs.push_back(ray->direction);
  }
  double max_angle_deg = 0;
  for (size_t a = 0; a < dirs.size(); ++a) {
    for (size_t b = a + 1; b < dirs.size(); ++b) {
      const double c = std::clamp(dirs[a].dot(dirs[b]), -1.0, 1.0);
      max_angle_deg = std::max(max_angle_deg, std::acos(c) * kRadToDeg);
    }
  }
  if (max_angle_deg < o.min_angle_deg) {
    result.status = TriangulationStatus::kDegenerate;
    return result;
  }
  const auto linear = TriangulateLinear(cameras, views);
  if (!linear) {
    result.status = TriangulationStatus::kDegenerate;
    return result;
  }
  Eigen::Vector3d p = *linear;
  if (!InFrontOfAll(cameras, views, p, o.min_depth_m)) {
    result.status = TriangulationStatus::kBehindCamera;
    result.point_world = p;
    return result;
  }
  Refine(cameras, views, candidate_index, false, o, &p, &result);
  result.status = InFrontOfAll(cameras, views, p, o.min_depth_m)
                      ? TriangulationStatus::kOk
                      : TriangulationStatus::kBehindCamera;
  return result;
}

}  // namespace

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
  CheckFinite(max_below_ground_m, "TriangulationOptions.max_below_ground_m");
  CheckPositive(prior_gate_m, "TriangulationOptions.prior_gate_m");
  FV_REQUIRE(max_radius_ratio == 0.0 || max_radius_ratio > 1.0,
             "TriangulationOptions.max_radius_ratio must be 0 (off) or > 1 (got {})",
             max_radius_ratio);
  FV_REQUIRE(weak_max_radius_ratio == 0.0 || weak_max_radius_ratio > 1.0,
             "TriangulationOptions.weak_max_radius_ratio must be 0 (off) or > 1 (got {})",
             weak_max_radius_ratio);
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

RayPairResult ClosestPointOfRays(const Ray3d& a, const Ray3d& b, double min_angle_deg) {
  FV_REQUIRE(a.origin.allFinite() && a.direction.allFinite() && b.origin.allFinite() &&
                 b.direction.allFinite(),
             "ClosestPointOfRays: a ray has a non-finite origin or direction");
  RayPairResult r;
  const double na = a.direction.norm(), nb = b.direction.norm();
  if (!(na > 0) || !(nb > 0)) return r;  // kParallel: no direction
  const Eigen::Vector3d u = a.direction / na, v = b.direction / nb;
  const double c = std::clamp(u.dot(v), -1.0, 1.0);
  r.angle_deg = std::acos(c) * kRadToDeg;
  if (r.angle_deg < min_angle_deg || 180.0 - r.angle_deg < min_angle_deg) {
    // Parallel: report the distance between the lines, no point.
    const Eigen::Vector3d w = b.origin - a.origin;
    r.gap_m = (w - w.dot(u) * u).norm();
    r.status = RayPairStatus::kParallel;
    return r;
  }
  // Minimise |a.o + s u - (b.o + t v)|^2 (unit directions): closed form.
  const Eigen::Vector3d w0 = a.origin - b.origin;
  const double d = u.dot(w0), e = v.dot(w0);
  const double denom = 1.0 - c * c;
  const double s = (c * e - d) / denom;
  const double t = (e - c * d) / denom;
  const Eigen::Vector3d pa = a.origin + s * u, pb = b.origin + t * v;
  r.midpoint = 0.5 * (pa + pb);
  r.gap_m = (pa - pb).norm();
  r.s_a = s / na;
  r.s_b = t / nb;
  r.status = (s > 0 && t > 0) ? RayPairStatus::kOk : RayPairStatus::kBehind;
  return r;
}

std::optional<Eigen::Vector2d> PredictBallCentre(const Camera& camera,
                                                 const Eigen::Vector3d& point_world,
                                                 double radius_m) {
  const CameraBlock block(camera);
  Eigen::Vector2d uv;
  if (!PredictCentre(block, radius_m, point_world.data(), uv.data())) return std::nullopt;
  return uv;
}

std::optional<Eigen::Vector3d> TriangulateLinear(const std::vector<Camera>& cameras,
                                                 const std::vector<View>& views) {
  if (views.size() < 2) return std::nullopt;
  // Centre the world on the mean camera centre for conditioning.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const View& v : views) {
    CheckCamera(cameras, v.camera);
    centre += cameras[v.camera].CentreInWorld();
  }
  centre /= static_cast<double>(views.size());
  Eigen::MatrixXd a(2 * views.size(), 4);
  for (size_t i = 0; i < views.size(); ++i) {
    const Camera& cam = cameras[views[i].camera];
    CheckObservation(views[i].observation, "triangulation");
    const auto xn = cam.Undistort(views[i].observation.centre_px);
    if (!xn) return std::nullopt;
    // P = [R | t + R c] maps the centred point to the camera.
    Eigen::Matrix<double, 3, 4> p;
    p.leftCols<3>() = cam.cam_from_world.rotation;
    p.col(3) = cam.cam_from_world.translation + cam.cam_from_world.rotation * centre;
    // Weight each view by 1 / sigma in normalized units and normalise the rows' scale.
    const double w = std::sqrt(cam.fx * cam.fy) / views[i].observation.sigma_px;
    Eigen::RowVector4d r0 = xn->x() * p.row(2) - p.row(0);
    Eigen::RowVector4d r1 = xn->y() * p.row(2) - p.row(1);
    const double depth_scale = p.row(2).head<3>().norm();  // unit: rows are in metres
    a.row(2 * i) = w * r0 / depth_scale;
    a.row(2 * i + 1) = w * r1 / depth_scale;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d x = svd.matrixV().col(3);
  if (!x.allFinite() || std::abs(x(3)) < 1e-12 * x.head<3>().norm()) return std::nullopt;
  const Eigen::Vector3d p = x.head<3>() / x(3) + centre;
  if (!p.allFinite()) return std::nullopt;
  return p;
}

TriangulationResult TriangulatePoint(const std::vector<Camera>& cameras,
                                     const std::vector<View>& views,
                                     const TriangulationOptions& options) {
  options.Check();
  for (const View& v : views) {
    CheckCamera(cameras, v.camera);
    CheckObservation(v.observation, fmt::format("triangulation camera {}", v.camera));
  }
  return TriangulateViews(cameras, views, {}, options);
}

TriangulationResult LocateOnGround(const Camera& camera, int camera_index,
                                   const BallObservation& observation,
                                   const TriangulationOptions& options) {
  options.Check();
  FV_REQUIRE(camera.has_pose, "LocateOnGround: camera '{}' has no pose", camera.name);
  CheckObservation(observation, "LocateOnGround");
  TriangulationResult result;
  const auto ray = camera.RayFromPixel(observation.centre_px);
  if (!ray) {
    result.status = TriangulationStatus::kDegenerate;
    return result;
  }
  const auto hit = IntersectHorizontalPlane(*ray, options.ball_radius_m);
  if (!hit || !(Depth(camera, *hit) > options.min_depth_m)) {
    result.status = TriangulationStatus::kBehindCamera;
    return result;
  }
  Eigen::Vector3d p(hit->x(), hit->y(), options.ball_radius_m);
  std::vector<Camera> cams = {camera};
  std::vector<View> views = {{0, observation}};
  Refine(cams, views, {0}, true, options, &p, &result);
  for (auto& v : result.views) v.camera = camera_index;
  result.on_ground = true;
  result.status = Depth(camera, p) > options.min_depth_m ? TriangulationStatus::kOk
                                                         : TriangulationStatus::kBehindCamera;
  return result;
}

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
