#include "fieldvision/calib/extrinsics.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>

#include "fieldvision/calib/costs.h"
#include "fieldvision/camera/opencv_camera.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"

namespace fv::calib {
namespace {

// RMS distance of the points from their best-fitting line.
template <int N>
double SpreadOffLine(const std::vector<Eigen::Matrix<double, N, 1>>& pts) {
  Eigen::Matrix<double, N, 1> mean = Eigen::Matrix<double, N, 1>::Zero();
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  Eigen::MatrixXd a(pts.size(), N);
  for (size_t i = 0; i < pts.size(); ++i) a.row(i) = (pts[i] - mean).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a);
  const auto& s = svd.singularValues();
  double off = 0;
  for (int i = 1; i < s.size(); ++i) off += s(i) * s(i);
  return std::sqrt(off / pts.size());
}

struct Candidate {
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  double sq_err = 0;
};

Candidate Score(const cv::Mat& rvec, const cv::Mat& tvec, const std::vector<cv::Point3d>& obj,
                const std::vector<cv::Point2d>& img, const cv::Mat& k, const cv::Mat& d,
                double threshold_px) {
  Candidate c{rvec.clone(), tvec.clone(), {}, 0};
  std::vector<cv::Point2d> proj;
  cv::projectPoints(obj, rvec, tvec, k, d, proj);
  // Points behind the camera never count.
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  for (size_t i = 0; i < obj.size(); ++i) {
    const cv::Mat pc = r * cv::Mat(obj[i]) + tvec;
    if (pc.at<double>(2) <= 0) continue;
    const double e = cv::norm(proj[i] - img[i]);
    if (e <= threshold_px) {
      c.inliers.push_back(static_cast<int>(i));
      c.sq_err += e * e;
    }
  }
  return c;
}

bool Better(const Candidate& a, const Candidate& b) {
  if (a.inliers.size() != b.inliers.size()) return a.inliers.size() > b.inliers.size();
  return a.sq_err < b.sq_err;
}

}  // namespace

void RequireInImage(const Eigen::Vector2d& uv_px, int width, int height, const std::string& where) {
  if (width <= 0 || height <= 0) return;
  constexpr double kMarginPx = 1.0;
  const auto inside = [&](int w, int h) {
    return uv_px.x() >= -0.5 - kMarginPx && uv_px.x() <= w - 0.5 + kMarginPx &&
           uv_px.y() >= -0.5 - kMarginPx && uv_px.y() <= h - 0.5 + kMarginPx;
  };
  if (inside(width, height)) return;
  Throw("{}: the point at ({:.1f}, {:.1f}) px lies outside the {}x{} image{}", where, uv_px.x(),
        uv_px.y(), width, height,
        inside(height, width)
            ? fmt::format(" (it would fit {}x{}: are width and height swapped?)", height, width)
            : std::string());
}

std::vector<PointCorrespondence> ReadPointsCsv(const std::string& path,
                                               const field::FieldModel* field, int width,
                                               int height) {
  const util::CsvTable t = util::CsvTable::Read(path);
  std::vector<PointCorrespondence> pts;
  const bool xyz = t.Has("x") && t.Has("y") && t.Has("z");
  FV_REQUIRE(t.Has("u") && t.Has("v") && (xyz || t.Has("name")),
             "points file '{}' needs the columns u,v,x,y,z or u,v,name", path);
  for (size_t r = 0; r < t.rows(); ++r) {
    PointCorrespondence p;
    p.uv_px = {t.GetDouble(r, "u"), t.GetDouble(r, "v")};
    FV_REQUIRE(p.uv_px.allFinite(), "{}: u and v must be finite", t.Where(r));
    RequireInImage(p.uv_px, width, height, t.Where(r));
    if (t.Has("name")) p.name = t.Get(r, "name");
    if (xyz) {
      p.p_world = {t.GetDouble(r, "x"), t.GetDouble(r, "y"), t.GetDouble(r, "z")};
      FV_REQUIRE(p.p_world.allFinite(), "{}: x, y and z must be finite", t.Where(r));
      if (p.name.empty()) p.name = fmt::format("row {}", r + 1);
    } else {
      FV_REQUIRE(field != nullptr, "{}: point '{}' is named but no field model was given (--field)",
                 t.Where(r), p.name);
      const field::FieldKeypoint* k = field->FindKeypoint(p.name);
      if (k == nullptr) {
        std::string known;
        for (size_t i = 0; i < field->keypoints.size() && i < 6; ++i) {
          known += (i ? ", " : "") + field->keypoints[i].name;
        }
        Throw(
            "{}: unknown keypoint '{}' in field '{}' (known: {}, ...; see `fieldvision field "
            "show {}`)",
            t.Where(r), p.name, field->name, known, field->name);
      }
      p.p_world = k->position_m;
    }
    pts.push_back(p);
  }
  return pts;
}

void ExtrinsicsOptions::Check() const {
  CheckPositive(ransac_threshold_px, "ransac_threshold_px");
  FV_REQUIRE(ransac_iterations >= 1, "ransac_iterations must be >= 1 (got {})", ransac_iterations);
  CheckInRange(ransac_confidence, 0.5, 1.0, "ransac_confidence");
  FV_REQUIRE(min_points >= 4, "min_points must be >= 4 (got {})", min_points);
  CheckNonNegative(min_line_spread_m, "min_line_spread_m");
  FV_REQUIRE(max_iterations >= 1, "max_iterations must be >= 1 (got {})", max_iterations);
}

std::string ExtrinsicsResult::Summary() const {
  return fmt::format(
      "{} of {} points inliers, reprojection rms {:.2f} px (max {:.2f}), on the field mean {:.0f} "
      "mm (max {:.0f}); camera at ({:.3f}, {:.3f}, {:.3f}) m; {} iterations",
      num_inliers, points.size(), rms_px, max_err_px, mean_err_mm, max_err_mm,
      camera_position_m.x(), camera_position_m.y(), camera_position_m.z(), iterations);
}

std::vector<PointResidual> PointResiduals(const camera::Camera& camera,
                                          const std::vector<PointCorrespondence>& points) {
  FV_REQUIRE(camera.has_pose, "camera '{}' has no pose (rvec/tvec)", camera.name);
  std::vector<PointResidual> out;
  for (const auto& p : points) {
    PointResidual r;
    r.name = p.name;
    r.uv_px = p.uv_px;
    r.p_world = p.p_world;
    const auto proj = camera.Project(p.p_world);
    if (proj) {
      r.projected_px = *proj;
      r.err_px = (*proj - p.uv_px).norm();
    } else {
      r.projected_px.setConstant(std::nan(""));
      r.err_px = std::numeric_limits<double>::infinity();
    }
    if (const auto ray = camera.RayFromPixel(p.uv_px)) {
      if (const auto hit = geometry::IntersectHorizontalPlane(*ray, p.p_world.z())) {
        r.err_mm = 1000.0 * (hit->head<2>() - p.p_world.head<2>()).norm();
      }
    }
    out.push_back(r);
  }
  return out;
}

ExtrinsicsResult EstimatePose(const camera::Camera& intrinsics,
                              const std::vector<PointCorrespondence>& points,
                              const ExtrinsicsOptions& options) {
  options.Check();
  intrinsics.Check("camera");
  const int n = static_cast<int>(points.size());
  FV_REQUIRE(n >= options.min_points, "only {} points given; a pose needs at least {}", n,
             options.min_points);
  std::vector<Eigen::Vector3d> world;
  std::vector<Eigen::Vector2d> pixels;
  for (const auto& p : points) {
    FV_REQUIRE(p.uv_px.allFinite() && p.p_world.allFinite(), "point '{}' is not finite", p.name);
    world.push_back(p.p_world);
    pixels.push_back(p.uv_px);
  }
  const double spread_m = SpreadOffLine<3>(world);
  FV_REQUIRE(spread_m >= options.min_line_spread_m,
             "the {} world points are (nearly) on one line ({:.3f} m off it); a pose needs points "
             "spread in two directions",
             n, spread_m);
  const double spread_px = SpreadOffLine<2>(pixels);
  FV_REQUIRE(spread_px >= 1.0,
             "the {} clicked pixels are on one line ({:.2f} px off it); the camera sees the points "
             "edge-on",
             n, spread_px);

  const cv::Mat k(camera::IntrinsicMatrix(intrinsics));
  cv::Mat d = camera::DistortionRow(intrinsics);
  std::vector<cv::Point3d> obj;
  std::vector<cv::Point2d> img;
  for (const auto& p : points) {
    obj.emplace_back(p.p_world.x(), p.p_world.y(), p.p_world.z());
    img.emplace_back(p.uv_px.x(), p.uv_px.y());
  }
  // Candidates: SQPnP on all points and RANSAC with minimal AP3P sets.
  Candidate best;
  bool have = false;
  auto consider = [&](const cv::Mat& rvec, const cv::Mat& tvec) {
    const Candidate c = Score(rvec, tvec, obj, img, k, d, options.ransac_threshold_px);
    if (!have || Better(c, best)) {
      best = c;
      have = true;
    }
  };
  try {
    cv::Mat rvec, tvec;
    if (cv::solvePnP(obj, img, k, d, rvec, tvec, false, cv::SOLVEPNP_SQPNP)) consider(rvec, tvec);
  } catch (const cv::Exception&) {
  }
  try {
    cv::Mat rvec, tvec;
    std::vector<int> inl;
    if (cv::solvePnPRansac(obj, img, k, d, rvec, tvec, false, options.ransac_iterations,
                           static_cast<float>(options.ransac_threshold_px),
                           options.ransac_confidence, inl, cv::SOLVEPNP_AP3P)) {
      consider(rvec, tvec);
    }
  } catch (const cv::Exception&) {
  }
  FV_REQUIRE(have && best.inliers.size() >= 4,
             "no camera pose puts 4 of the {} points within {:.1f} px of their clicks (check the "
             "names, the order of u and v, and the camera's intrinsics)",
             n, options.ransac_threshold_px);

  ExtrinsicsResult result;
  Eigen::Vector3d rvec(best.rvec.at<double>(0), best.rvec.at<double>(1), best.rvec.at<double>(2));
  Eigen::Vector3d tvec(best.tvec.at<double>(0), best.tvec.at<double>(1), best.tvec.at<double>(2));
  std::vector<int> inliers = best.inliers;
  if (options.refine) {
    const auto intr = intrinsics.IntrinsicsBlock();
    for (int round = 0; round < 2; ++round) {
      ceres::Problem problem;
      for (int i : inliers) {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<FixedPointReprojection, 2, 3, 3>(
                new FixedPointReprojection(intr, points[i].uv_px, points[i].p_world)),
            nullptr, rvec.data(), tvec.data());
      }
      ceres::Solver::Options so;
      so.linear_solver_type = ceres::DENSE_QR;
      so.max_num_iterations = options.max_iterations;
      ceres::Solver::Summary summary;
      ceres::Solve(so, &problem, &summary);
      result.iterations += static_cast<int>(summary.iterations.size());
      // Points that now fit join the inliers (and those that no longer fit leave).
      const cv::Mat rv = (cv::Mat_<double>(3, 1) << rvec.x(), rvec.y(), rvec.z());
      const cv::Mat tv = (cv::Mat_<double>(3, 1) << tvec.x(), tvec.y(), tvec.z());
      const Candidate c = Score(rv, tv, obj, img, k, d, options.ransac_threshold_px);
      if (c.inliers == inliers || c.inliers.size() < 4) break;
      inliers = c.inliers;
    }
  }
  result.camera = intrinsics;
  result.camera.has_pose = true;
  result.camera.cam_from_world = geometry::Rigid3d::FromRvecTvec(rvec, tvec);
  result.camera_position_m = result.camera.CentreInWorld();
  result.points = PointResiduals(result.camera, points);
  double sq = 0, mm = 0;
  int n_mm = 0;
  for (auto& r : result.points) r.inlier = false;
  for (int i : inliers) {
    auto& r = result.points[i];
    r.inlier = true;
    sq += r.err_px * r.err_px;
    result.max_err_px = std::max(result.max_err_px, r.err_px);
    if (r.err_mm) {
      mm += *r.err_mm;
      result.max_err_mm = std::max(result.max_err_mm, *r.err_mm);
      ++n_mm;
    }
  }
  result.num_inliers = static_cast<int>(inliers.size());
  result.rms_px = std::sqrt(sq / inliers.size());
  result.mean_err_mm = n_mm ? mm / n_mm : 0.0;
  return result;
}

}  // namespace fv::calib
