#include "fieldvision/calib/rig.h"

#include <cmath>
#include <map>
#include <set>

#include <ceres/ceres.h>
#include <fmt/format.h>
#include <Eigen/Dense>

#include "fieldvision/calib/costs.h"
#include "fieldvision/calib/extrinsics.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"

namespace fv::calib {
namespace {

double RmsPx(const camera::Camera& cam, const std::vector<RigObservation>& obs,
             const std::map<std::string, Eigen::Vector3d>& points) {
  double sq = 0;
  int n = 0;
  for (const auto& o : obs) {
    const auto uv = cam.Project(points.at(o.name));
    if (!uv) continue;
    sq += (*uv - o.uv_px).squaredNorm();
    ++n;
  }
  return n ? std::sqrt(sq / n) : 0.0;
}

}  // namespace

std::vector<RigObservation> ReadRigObservations(const std::string& path,
                                                const field::FieldModel* field, int width,
                                                int height) {
  const util::CsvTable t = util::CsvTable::Read(path);
  t.Require({"u", "v", "name"});
  const bool xyz = t.Has("x") && t.Has("y") && t.Has("z");
  std::vector<RigObservation> out;
  for (size_t r = 0; r < t.rows(); ++r) {
    RigObservation o;
    o.name = t.Get(r, "name");
    FV_REQUIRE(!o.name.empty(), "{}: empty point name", t.Where(r));
    o.uv_px = {t.GetDouble(r, "u"), t.GetDouble(r, "v")};
    FV_REQUIRE(o.uv_px.allFinite(), "{}: u and v must be finite", t.Where(r));
    RequireInImage(o.uv_px, width, height, t.Where(r));
    if (xyz && !t.Get(r, "x").empty()) {
      o.p_world = Eigen::Vector3d(t.GetDouble(r, "x"), t.GetDouble(r, "y"), t.GetDouble(r, "z"));
      FV_REQUIRE(o.p_world->allFinite(), "{}: x, y and z must be finite", t.Where(r));
    } else if (field != nullptr) {
      if (const field::FieldKeypoint* k = field->FindKeypoint(o.name)) o.p_world = k->position_m;
    }
    out.push_back(o);
  }
  return out;
}

void RigOptions::Check() const {
  CheckPositive(huber_px, "huber_px");
  FV_REQUIRE(max_iterations >= 1, "max_iterations must be >= 1 (got {})", max_iterations);
  FV_REQUIRE(min_known_points >= 3, "min_known_points must be >= 3 (got {})", min_known_points);
  FV_REQUIRE(min_observations_per_camera >= 3, "min_observations_per_camera must be >= 3 (got {})",
             min_observations_per_camera);
}

std::string RigResult::Summary() const {
  std::string s = fmt::format(
      "rig of {} cameras, {} free points, cost {:.3g} -> {:.3g}, {} "
      "iterations",
      cameras.size(), free_points.size(), initial_cost, final_cost, iterations);
  for (const auto& r : reports) {
    s += fmt::format(
        "\n  {}: {} observations, rms {:.2f} -> {:.2f} px, moved {:.1f} mm, turned "
        "{:.3f} deg",
        r.name, r.num_observations, r.rms_before_px, r.rms_after_px, r.moved_mm, r.rotated_deg);
  }
  return s;
}

RigResult RefineRig(const std::vector<camera::Camera>& cameras,
                    const std::vector<std::vector<RigObservation>>& observations,
                    const RigOptions& options) {
  options.Check();
  FV_REQUIRE(cameras.size() >= 2, "a rig needs at least 2 cameras (got {})", cameras.size());
  FV_REQUIRE(observations.size() == cameras.size(),
             "{} cameras but {} observation lists; give one per camera", cameras.size(),
             observations.size());
  auto cam_name = [&](size_t i) {
    return cameras[i].name.empty() ? fmt::format("camera {}", i + 1) : cameras[i].name;
  };
  std::map<std::string, Eigen::Vector3d> known;
  std::map<std::string, std::vector<size_t>> free_seen_by;
  for (size_t i = 0; i < cameras.size(); ++i) {
    cameras[i].Check(cam_name(i));
    FV_REQUIRE(cameras[i].has_pose, "{} has no pose; calibrate its extrinsics first", cam_name(i));
    FV_REQUIRE(static_cast<int>(observations[i].size()) >= options.min_observations_per_camera,
               "{} has {} observations; at least {} are needed", cam_name(i),
               observations[i].size(), options.min_observations_per_camera);
    for (const auto& o : observations[i]) {
      if (o.p_world) {
        auto [it, inserted] = known.emplace(o.name, *o.p_world);
        FV_REQUIRE(inserted || (it->second - *o.p_world).norm() < 1e-9,
                   "point '{}' has two different positions", o.name);
      } else {
        free_seen_by[o.name].push_back(i);
      }
    }
  }
  for (const auto& [name, cams] : free_seen_by) {
    FV_REQUIRE(!known.count(name), "point '{}' is known in one list and free in another", name);
    FV_REQUIRE(std::set<size_t>(cams.begin(), cams.end()).size() >= 2,
               "point '{}' has no known position and is seen by {} only; name a field keypoint or "
               "observe it from a second camera",
               name, cam_name(cams.front()));
  }
  FV_REQUIRE(static_cast<int>(known.size()) >= options.min_known_points,
             "the rig has {} points of known position; at least {} fix its place and scale",
             known.size(), options.min_known_points);

  // Free points start at the point closest to their rays.
  std::map<std::string, Eigen::Vector3d> points = known;
  for (const auto& [name, cams] : free_seen_by) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < cameras.size(); ++i) {
      for (const auto& o : observations[i]) {
        if (o.name != name) continue;
        const auto ray = cameras[i].RayFromPixel(o.uv_px);
        FV_REQUIRE(ray.has_value(), "{}: pixel of point '{}' cannot be undistorted", cam_name(i),
                   name);
        const Eigen::Matrix3d m =
            Eigen::Matrix3d::Identity() - ray->direction * ray->direction.transpose();
        a += m;
        b += m * ray->origin;
      }
    }
    FV_REQUIRE(std::abs(a.determinant()) > 1e-12,
               "point '{}': its rays are parallel; it cannot be placed", name);
    points[name] = a.ldlt().solve(b);
  }

  RigResult result;
  result.cameras = cameras;
  std::vector<Eigen::Vector3d> rvecs, tvecs;
  for (const auto& c : cameras) {
    rvecs.push_back(c.cam_from_world.Rvec());
    tvecs.push_back(c.cam_from_world.translation);
  }
  std::map<std::string, Eigen::Vector3d> free_params;
  for (const auto& [name, cams] : free_seen_by) free_params[name] = points[name];
  ceres::Problem problem;
  for (size_t i = 0; i < cameras.size(); ++i) {
    const auto intr = cameras[i].IntrinsicsBlock();
    for (const auto& o : observations[i]) {
      if (o.p_world) {
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<FixedPointReprojection, 2, 3, 3>(
                                     new FixedPointReprojection(intr, o.uv_px, *o.p_world)),
                                 new ceres::HuberLoss(options.huber_px), rvecs[i].data(),
                                 tvecs[i].data());
      } else {
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<FreePointReprojection, 2, 3, 3, 3>(
                                     new FreePointReprojection(intr, o.uv_px)),
                                 new ceres::HuberLoss(options.huber_px), rvecs[i].data(),
                                 tvecs[i].data(), free_params[o.name].data());
      }
    }
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_SCHUR;
  so.max_num_iterations = options.max_iterations;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  result.iterations = static_cast<int>(summary.iterations.size());
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  FV_REQUIRE(summary.IsSolutionUsable(), "rig adjustment failed: {}", summary.message);

  std::map<std::string, Eigen::Vector3d> refined_points = known;
  for (const auto& [name, p] : free_params) {
    refined_points[name] = p;
    result.free_points.emplace_back(name, p);
  }
  for (size_t i = 0; i < cameras.size(); ++i) {
    camera::Camera& c = result.cameras[i];
    c.cam_from_world = geometry::Rigid3d::FromRvecTvec(rvecs[i], tvecs[i]);
    RigCameraReport rep;
    rep.name = cam_name(i);
    rep.num_observations = static_cast<int>(observations[i].size());
    rep.rms_before_px = RmsPx(cameras[i], observations[i], points);
    rep.rms_after_px = RmsPx(c, observations[i], refined_points);
    rep.moved_mm = 1000.0 * (c.CentreInWorld() - cameras[i].CentreInWorld()).norm();
    rep.rotated_deg = geometry::RotationAngleBetween(c.cam_from_world.rotation,
                                                     cameras[i].cam_from_world.rotation) *
                      180.0 / M_PI;
    result.reports.push_back(rep);
  }
  return result;
}

}  // namespace fv::calib
