#include "fieldvision/calib/rig_place.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>
#include <Eigen/Dense>

#include "fieldvision/calib/costs.h"
#include "fieldvision/camera/projection.h"
#include "fieldvision/util/error.h"

namespace fv::calib {
namespace {

// A world point seen by camera i of the rig: p_ref = R p + t (ref_from_world), then the camera's
// fixed pose in the rig and its intrinsics (FixedPointReprojection's projection).
struct RigPointCost {
  RigPointCost(const camera::Camera& cam, const Eigen::Vector2d& uv, const Eigen::Vector3d& p)
      : project(cam.IntrinsicsBlock(), uv, Eigen::Vector3d::Zero()),
        cam_r(cam.cam_from_world.Rvec()),
        cam_t(cam.cam_from_world.translation),
        p(p) {}
  template <typename T>
  bool operator()(const T* r, const T* t, T* residual) const {
    const T pw[3] = {T(p.x()), T(p.y()), T(p.z())};
    T p_ref[3];
    ceres::AngleAxisRotatePoint(r, pw, p_ref);
    for (int k = 0; k < 3; ++k) p_ref[k] += t[k];
    const T cr[3] = {T(cam_r[0]), T(cam_r[1]), T(cam_r[2])};
    const T ct[3] = {T(cam_t[0]), T(cam_t[1]), T(cam_t[2])};
    return project.Project(cr, ct, p_ref, residual);
  }
  FixedPointReprojection project;  // the intrinsics and the pixel (its own point is unused)
  Eigen::Vector3d cam_r, cam_t, p;
};

struct Obs {
  int camera;
  int index;
  Eigen::Vector2d uv;
  Eigen::Vector3d p;
};

// Linear generalized PnP: every observation's ray constraint (x p_z - p_x = 0, y p_z - p_y = 0 on
// p_cam = A (R p + t) + b) stacked in the unknowns R, t and a homogeneous scale.
std::vector<geometry::Rigid3d> LinearRigPose(const std::vector<camera::Camera>& rig,
                                             const std::vector<Obs>& obs) {
  bool planar = true;
  bool offset = false;
  for (const auto& o : obs) planar = planar && std::abs(o.p.z()) < 1e-9;
  for (const auto& o : obs) {
    offset = offset || rig[o.camera].cam_from_world.translation.norm() > 1e-9;
  }
  // Columns: R row-major (9), t (3), s (1); planar points drop R's third column (2, 5, 8).
  std::vector<int> cols;
  for (int k = 0; k < 13; ++k) {
    if (planar && (k == 2 || k == 5 || k == 8)) continue;
    if (!offset && k == 12) continue;
    cols.push_back(k);
  }
  Eigen::MatrixXd a(2 * obs.size(), cols.size());
  for (size_t i = 0; i < obs.size(); ++i) {
    const camera::Camera& cam = rig[obs[i].camera];
    const auto n = cam.Undistort(obs[i].uv);
    if (!n) return {};
    Eigen::Matrix<double, 3, 13> m = Eigen::Matrix<double, 3, 13>::Zero();
    for (Eigen::Index k = 0; k < 3; ++k) {
      m.block<1, 3>(k, 3 * k) = obs[i].p.transpose();
      m(k, 9 + k) = 1.0;
    }
    Eigen::Matrix<double, 3, 13> full;
    full.leftCols<12>() = cam.cam_from_world.rotation * m.leftCols<12>();
    full.col(12) = cam.cam_from_world.translation;
    const Eigen::RowVector3d c1(-1, 0, n->x()), c2(0, -1, n->y());
    const Eigen::Matrix<double, 1, 13> r1 = c1 * full, r2 = c2 * full;
    for (size_t j = 0; j < cols.size(); ++j) {
      a(2 * i, j) = r1(cols[j]);
      a(2 * i + 1, j) = r2(cols[j]);
    }
  }
  if (a.rows() < static_cast<int>(cols.size()) - 1) return {};
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  // The smallest singular vectors: few points per camera leave spurious exact null vectors
  // (R = 0 with t at a camera centre; a rank-1 R with t = 0), so each of the last three is a
  // candidate and the caller keeps the one that fits best after refinement.
  std::vector<geometry::Rigid3d> out;
  const int nv = static_cast<int>(cols.size());
  for (int idx = nv - 1; idx >= std::max(0, nv - 3); --idx) {
    const Eigen::VectorXd v = svd.matrixV().col(idx);
    Eigen::Matrix<double, 13, 1> w = Eigen::Matrix<double, 13, 1>::Zero();
    for (size_t j = 0; j < cols.size(); ++j) w(cols[j]) = v(j);
    Eigen::Matrix3d r;
    r << w(0), w(1), w(2), w(3), w(4), w(5), w(6), w(7), w(8);
    double scale;
    if (offset) {
      if (std::abs(w(12)) < 1e-9) continue;
      scale = 1.0 / w(12);
    } else {
      const double norm = r.col(0).norm() + r.col(1).norm();
      if (norm < 1e-9) continue;
      scale = 2.0 / norm;
    }
    r *= scale;
    Eigen::Vector3d t = w.segment<3>(9) * scale;
    if (r.col(0).norm() < 1e-3 || r.col(1).norm() < 1e-3) continue;  // R = 0: spurious
    if (planar) r.col(2) = r.col(0).cross(r.col(1));
    for (int sign : {1, -1}) {
      if (sign < 0 && offset) break;  // the offset fixes the sign
      Eigen::Matrix3d rs = sign * r;
      if (planar) rs.col(2) = rs.col(0).cross(rs.col(1));
      const Eigen::JacobiSVD<Eigen::Matrix3d> svd3(rs, Eigen::ComputeFullU | Eigen::ComputeFullV);
      const Eigen::Matrix3d rot = svd3.matrixU() * svd3.matrixV().transpose();
      if (rot.determinant() < 0 || !rot.allFinite()) continue;
      out.push_back(geometry::Rigid3d{rot, sign * t});
    }
  }
  return out;
}

// Given the rotation of ref_from_world, the translation is linear in the ray constraints.
std::optional<Eigen::Vector3d> TranslationFor(const std::vector<camera::Camera>& rig,
                                              const std::vector<Obs>& obs,
                                              const std::vector<Eigen::Vector2d>& rays,
                                              const Eigen::Matrix3d& r) {
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < obs.size(); ++i) {
    const geometry::Rigid3d& c = rig[obs[i].camera].cam_from_world;
    // c1 . (A (R p + t) + b) = 0, c2 . (...) = 0
    const Eigen::Vector3d q = c.rotation * (r * obs[i].p) + c.translation;
    const Eigen::RowVector3d c1(-1, 0, rays[i].x()), c2(0, -1, rays[i].y());
    for (const Eigen::RowVector3d& row : {c1, c2}) {
      const Eigen::RowVector3d at = row * c.rotation;
      ata += at.transpose() * at;
      atb -= at.transpose() * row.dot(q);
    }
  }
  if (std::abs(ata.determinant()) < 1e-12) return std::nullopt;
  return Eigen::Vector3d(ata.ldlt().solve(atb));
}

// Starts from rotations spread over SO(3) (deterministic pseudo-random unit quaternions), each
// with its best translation; the `keep` with the smallest truncated reprojection error.
std::vector<geometry::Rigid3d> SampledRigPoses(const std::vector<camera::Camera>& rig,
                                               const std::vector<Obs>& obs, int samples, int keep) {
  std::vector<Eigen::Vector2d> rays;
  for (const auto& o : obs) {
    const auto n = rig[o.camera].Undistort(o.uv);
    if (!n) return {};
    rays.push_back(*n);
  }
  std::mt19937 rng(12345);
  std::normal_distribution<double> normal;
  std::vector<std::pair<double, geometry::Rigid3d>> scored;
  for (int k = 0; k < samples; ++k) {
    Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
    q.normalize();
    const Eigen::Matrix3d r = q.toRotationMatrix();
    const auto t = TranslationFor(rig, obs, rays, r);
    if (!t) continue;
    double score = 0;
    for (size_t i = 0; i < obs.size(); ++i) {
      const camera::Camera& cam = rig[obs[i].camera];
      const auto uv = cam.ProjectFromCamera(cam.cam_from_world * (r * obs[i].p + *t));
      score += uv ? std::min((*uv - obs[i].uv).squaredNorm(), 2500.0) : 2500.0;
    }
    scored.emplace_back(score, geometry::Rigid3d{r, *t});
  }
  std::sort(scored.begin(), scored.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<geometry::Rigid3d> out;
  for (int k = 0; k < keep && k < static_cast<int>(scored.size()); ++k) {
    out.push_back(scored[k].second);
  }
  return out;
}

std::vector<camera::Camera> Placed(const std::vector<camera::Camera>& rig,
                                   const geometry::Rigid3d& ref_from_world) {
  std::vector<camera::Camera> out = rig;
  for (auto& c : out) c.cam_from_world = c.cam_from_world * ref_from_world;
  return out;
}

}  // namespace

void RigPlacementOptions::Check() const {
  pnp.Check();
  CheckPositive(huber_px, "huber_px");
  CheckPositive(outlier_px, "outlier_px");
  FV_REQUIRE(max_iterations >= 1, "max_iterations must be >= 1 (got {})", max_iterations);
  FV_REQUIRE(min_points >= 3, "min_points must be >= 3 (got {})", min_points);
}

std::string RigPlacementResult::Summary() const {
  std::string s = fmt::format(
      "rig of {} cameras placed from {} points ({} inliers), reprojection rms {:.2f} px; start: "
      "{}; {} iterations",
      cameras.size(), num_points, num_inliers, rms_px_all, start, iterations);
  for (size_t i = 0; i < cameras.size(); ++i) {
    const Eigen::Vector3d c = cameras[i].CentreInWorld();
    s += fmt::format("\n  {}: at ({:.3f}, {:.3f}, {:.3f}) m", cameras[i].name, c.x(), c.y(), c.z());
    if (!points[i].empty()) {
      s += fmt::format(", {} points, rms {:.2f} px", points[i].size(), rms_px[i]);
    }
  }
  return s;
}

std::vector<camera::Camera> CarryRig(const std::vector<camera::Camera>& rig, int k,
                                     const geometry::Rigid3d& cam_k_from_world) {
  FV_REQUIRE(k >= 0 && k < static_cast<int>(rig.size()), "rig camera {} out of range", k);
  for (const auto& c : rig) {
    FV_REQUIRE(c.has_pose, "rig camera '{}' has no pose in the rig", c.name);
  }
  const geometry::Rigid3d ref_from_world = rig[k].cam_from_world.Inverse() * cam_k_from_world;
  return Placed(rig, ref_from_world);
}

namespace {  // The stages of PlaceRig.

std::vector<Obs> CollectObservations(const std::vector<camera::Camera>& rig,
                                     const std::vector<std::vector<PointCorrespondence>>& points,
                                     const RigPlacementOptions& options) {
  FV_REQUIRE(!rig.empty(), "the rig has no cameras");
  FV_REQUIRE(points.size() == rig.size(), "{} cameras but {} point lists", rig.size(),
             points.size());
  std::vector<Obs> obs;
  for (size_t i = 0; i < rig.size(); ++i) {
    rig[i].Check("rig camera '" + rig[i].name + "'");
    FV_REQUIRE(rig[i].has_pose, "rig camera '{}' has no pose in the rig (run calibrate multi)",
               rig[i].name);
    for (size_t j = 0; j < points[i].size(); ++j) {
      FV_REQUIRE(points[i][j].uv_px.allFinite() && points[i][j].p_world.allFinite(),
                 "camera '{}': point '{}' is not finite", rig[i].name, points[i][j].name);
      obs.push_back(
          {static_cast<int>(i), static_cast<int>(j), points[i][j].uv_px, points[i][j].p_world});
    }
  }
  FV_REQUIRE(static_cast<int>(obs.size()) >= options.min_points,
             "only {} points over the rig's cameras; placing the rig needs at least {}", obs.size(),
             options.min_points);
  return obs;
}

// The rig's placement (ref_from_world) fitted to the inlier observations from `start`.
geometry::Rigid3d RefinePlacement(const std::vector<camera::Camera>& rig,
                                  const std::vector<Obs>& obs, const RigPlacementOptions& options,
                                  const geometry::Rigid3d& start, const std::vector<bool>& inlier,
                                  int* iterations, double* cost) {
  Eigen::Vector3d r = start.Rvec(), t = start.translation;
  ceres::Problem problem;
  for (size_t k = 0; k < obs.size(); ++k) {
    if (!inlier[k]) continue;
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<RigPointCost, 2, 3, 3>(
                                 new RigPointCost(rig[obs[k].camera], obs[k].uv, obs[k].p)),
                             new ceres::HuberLoss(options.huber_px), r.data(), t.data());
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  if (iterations) *iterations += static_cast<int>(summary.iterations.size());
  if (cost) *cost = summary.IsSolutionUsable() ? summary.final_cost : 1e300;
  return geometry::Rigid3d::FromRvecTvec(r, t);
}

// Pixel error of every observation through the placed rig; 1e9 behind its camera.
std::vector<double> PlacementErrors(const std::vector<camera::Camera>& rig,
                                    const std::vector<Obs>& obs,
                                    const geometry::Rigid3d& ref_from_world) {
  const auto cams = Placed(rig, ref_from_world);
  std::vector<double> e(obs.size());
  for (size_t k = 0; k < obs.size(); ++k) {
    const auto uv = cams[obs[k].camera].Project(obs[k].p);
    e[k] = uv ? (*uv - obs[k].uv).norm() : 1e9;
  }
  return e;
}

// Starts: PnP in each camera with 4 or more points, the linear and the sampled rig poses.
std::vector<std::pair<std::string, geometry::Rigid3d>> PlacementStarts(
    const std::vector<camera::Camera>& rig,
    const std::vector<std::vector<PointCorrespondence>>& points, const std::vector<Obs>& obs,
    const RigPlacementOptions& options) {
  std::vector<std::pair<std::string, geometry::Rigid3d>> starts;
  for (size_t i = 0; i < rig.size(); ++i) {
    if (static_cast<int>(points[i].size()) < 4) continue;
    try {
      camera::Camera intr = rig[i];
      intr.has_pose = false;
      const ExtrinsicsResult e = EstimatePose(intr, points[i], options.pnp);
      starts.emplace_back("camera " + rig[i].name,
                          rig[i].cam_from_world.Inverse() * e.camera.cam_from_world);
    } catch (const Error&) {
    }
  }
  if (obs.size() >= 6) {
    for (const auto& lin : LinearRigPose(rig, obs)) {
      starts.emplace_back("all cameras (linear)", lin);
    }
  }
  for (const auto& sampled : SampledRigPoses(rig, obs, 4000, 6)) {
    starts.emplace_back("all cameras (sampled rotations)", sampled);
  }
  FV_REQUIRE(!starts.empty(),
             "the {} points cannot place the rig: give one camera 4 or more points, or 6 or more "
             "over several cameras, spread in two directions",
             obs.size());
  return starts;
}

// Every start refined; the most points within the outlier gate, then the lowest cost.
geometry::Rigid3d BestPlacement(
    const std::vector<camera::Camera>& rig, const std::vector<Obs>& obs,
    const std::vector<std::pair<std::string, geometry::Rigid3d>>& starts,
    const RigPlacementOptions& options, RigPlacementResult* result) {
  const std::vector<bool> all(obs.size(), true);
  double best_score = 1e300;
  geometry::Rigid3d best;
  for (const auto& [name, s] : starts) {
    // A start that puts a point behind its camera cannot be evaluated (Ceres would stop and
    // log); such starts are wrong anyway.
    const auto e0 = PlacementErrors(rig, obs, s);
    if (std::any_of(e0.begin(), e0.end(), [](double v) { return v >= 1e9; })) continue;
    double cost = 1e300;
    const geometry::Rigid3d r =
        RefinePlacement(rig, obs, options, s, all, &result->iterations, &cost);
    int in = 0;
    for (double v : PlacementErrors(rig, obs, r)) in += v <= options.outlier_px ? 1 : 0;
    const double score = cost - 1e6 * in;
    if (score < best_score) {
      best_score = score;
      best = r;
      result->start = name;
    }
  }
  FV_REQUIRE(result->start.size() > 0,
             "the {} points cannot place the rig: every start puts some point behind its camera "
             "(check the names and each camera's points file)",
             obs.size());
  return best;
}

// Cameras, per-point residuals and per-camera RMS of the placement.
void SetPlacementResiduals(const std::vector<camera::Camera>& rig,
                           const std::vector<std::vector<PointCorrespondence>>& points,
                           const std::vector<Obs>& obs, const RigPlacementOptions& options,
                           RigPlacementResult* result) {
  result->cameras = Placed(rig, result->ref_from_world);
  result->points.resize(rig.size());
  result->rms_px.assign(rig.size(), 0.0);
  result->num_points = static_cast<int>(obs.size());
  const auto e = PlacementErrors(rig, obs, result->ref_from_world);
  double sq_all = 0;
  for (size_t i = 0; i < rig.size(); ++i) {
    if (points[i].empty()) continue;
    result->points[i] = PointResiduals(result->cameras[i], points[i]);
    double sq = 0;
    int n = 0;
    for (size_t k = 0; k < obs.size(); ++k) {
      if (obs[k].camera != static_cast<int>(i)) continue;
      auto& pr = result->points[i][obs[k].index];
      pr.inlier = e[k] <= options.outlier_px;
      if (!pr.inlier) continue;
      sq += pr.err_px * pr.err_px;
      ++n;
    }
    result->rms_px[i] = n ? std::sqrt(sq / n) : 0.0;
    sq_all += sq;
    result->num_inliers += n;
  }
  result->rms_px_all = result->num_inliers ? std::sqrt(sq_all / result->num_inliers) : 0.0;
}

}  // namespace

RigPlacementResult PlaceRig(const std::vector<camera::Camera>& rig,
                            const std::vector<std::vector<PointCorrespondence>>& points,
                            const RigPlacementOptions& options) {
  options.Check();
  const std::vector<Obs> obs = CollectObservations(rig, points, options);
  RigPlacementResult result;
  geometry::Rigid3d best =
      BestPlacement(rig, obs, PlacementStarts(rig, points, obs, options), options, &result);
  // Leave out points far off, refit once.
  const auto e = PlacementErrors(rig, obs, best);
  std::vector<bool> inlier(obs.size());
  int n_in = 0;
  for (size_t k = 0; k < obs.size(); ++k) {
    inlier[k] = e[k] <= options.outlier_px;
    n_in += inlier[k] ? 1 : 0;
  }
  FV_REQUIRE(n_in >= 3,
             "no placement of the rig puts 3 of its {} points within {:.1f} px of their clicks "
             "(check the names and each camera's points file)",
             obs.size(), options.outlier_px);
  if (n_in < static_cast<int>(obs.size())) {
    best = RefinePlacement(rig, obs, options, best, inlier, &result.iterations, nullptr);
  }
  result.ref_from_world = best;
  SetPlacementResiduals(rig, points, obs, options, &result);
  return result;
}

}  // namespace fv::calib
