#include "fieldvision/calib/intrinsics.h"

#include <algorithm>
#include <array>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <numeric>

#include <fmt/format.h>
#include <Eigen/Core>
#include <opencv2/calib3d.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/strings.h"

namespace fv::calib {
namespace {

// calibrateCamera's stop: 100 iterations or no change at double precision.
cv::TermCriteria FitCriteria() {
  return {cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, DBL_EPSILON};
}

// OpenCV's flags for the options' model; with 5 coefficients k3 is fitted when k3_free.
int CalibFlags(const IntrinsicsOptions& o, bool k3_free) {
  int flags = 0;
  switch (o.num_distortion) {
    case 4:
      flags |= cv::CALIB_FIX_K3;
      break;
    case 5:
      if (!k3_free) flags |= cv::CALIB_FIX_K3;
      break;
    case 8:
      flags |= cv::CALIB_RATIONAL_MODEL;
      break;
    case 12:
      flags |= cv::CALIB_RATIONAL_MODEL | cv::CALIB_THIN_PRISM_MODEL;
      break;
    case 14:
      flags |= cv::CALIB_RATIONAL_MODEL | cv::CALIB_THIN_PRISM_MODEL | cv::CALIB_TILTED_MODEL;
      break;
  }
  if (o.fix_aspect_ratio) flags |= cv::CALIB_FIX_ASPECT_RATIO;
  if (o.zero_tangent) flags |= cv::CALIB_ZERO_TANGENT_DIST;
  if (o.fix_principal_point) flags |= cv::CALIB_FIX_PRINCIPAL_POINT;
  return flags;
}

// The distortion vector calibrateCamera fills for `flags`: OpenCV refuses a longer start (a
// 14-number start with the thin-prism model of 12).
cv::Mat ZeroDistortionFor(int flags) {
  const int n = (flags & cv::CALIB_TILTED_MODEL)       ? 14
                : (flags & cv::CALIB_THIN_PRISM_MODEL) ? 12
                : (flags & cv::CALIB_RATIONAL_MODEL)   ? 8
                                                       : 5;
  return cv::Mat::zeros(1, n, CV_64F);
}

std::string Today() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

}  // namespace

void CheckDistortionModel(int n) {
  FV_REQUIRE(n == 4 || n == 5 || n == 8 || n == 12 || n == 14,
             "num_distortion must be 4, 5, 8, 12 or 14 (got {})", n);
}

TermModel ParseTermModel(const std::string& name, const std::string& what) {
  const std::string n = util::ToLower(name);
  if (n == "auto") return TermModel::kAuto;
  if (n == "free") return TermModel::kFree;
  if (n == "zero") return TermModel::kZero;
  Throw("{} '{}' is not known; use auto, free or zero", what, name);
}

double CornerShiftPx(const camera::Camera& a, const camera::Camera& b) {
  FV_REQUIRE(a.width == b.width && a.height == b.height,
             "corner shift: the cameras are {}x{} and {}x{}", a.width, a.height, b.width, b.height);
  const double w = a.width - 1.0, h = a.height - 1.0;
  const std::array<Eigen::Vector2d, 4> corners = {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0),
                                                  Eigen::Vector2d(0, h), Eigen::Vector2d(w, h)};
  double worst = 0;
  for (const Eigen::Vector2d& corner : corners) {
    const auto ray = a.Undistort(corner);
    const auto back = ray ? b.ProjectFromCamera(ray->homogeneous()) : std::nullopt;
    if (!back) return std::numeric_limits<double>::infinity();
    worst = std::max(worst, (*back - corner).norm());
  }
  return worst;
}

void IntrinsicsOptions::Check() const {
  board.Check();
  detect.Check();
  source.Check();
  CheckDistortionModel(num_distortion);
  CheckPositive(outlier_factor, "outlier_factor");
  CheckNonNegative(outlier_min_px, "outlier_min_px");
  CheckInRange(max_drop_fraction, 0.0, 0.9, "max_drop_fraction");
  FV_REQUIRE(min_views >= 1, "min_views must be >= 1 (got {})", min_views);
  FV_REQUIRE(coverage_grid >= 1 && coverage_grid <= 32, "coverage_grid must be in [1, 32] (got {})",
             coverage_grid);
  CheckInRange(focal_profile_factor, 1.01, 4.0, "focal_profile_factor");
  CheckNonNegative(focal_profile_min_gain, "focal_profile_min_gain");
}

std::string CoverageReport::Describe() const {
  std::string s = fmt::format(
      "corners reach {:.0f}% of {}x{} image cells, {:.0f}% of the half "
      "diagonal; board tilt range {:.0f} deg",
      100 * cell_fraction, grid, grid, 100 * radius_fraction, tilt_range_deg);
  for (int r = 0; r < grid; ++r) {
    s += "\n  ";
    for (int c = 0; c < grid; ++c) s += fmt::format("{:5d}", corners_per_cell[r * grid + c]);
  }
  return s;
}

std::string IntrinsicsResult::Summary() const {
  std::string s = fmt::format(
      "rms {:.3f} px over {} of {} views ({} images, {} fits); fx {:.2f} fy {:.2f} cx {:.2f} cy "
      "{:.2f} px (std {:.2f} {:.2f} {:.2f} {:.2f}); distortion [",
      rms_px, num_used, num_found, num_images, fits, camera.fx, camera.fy, camera.cx, camera.cy,
      std_fx_px, std_fy_px, std_cx_px, std_cy_px);
  for (size_t i = 0; i < camera.distortion.size(); ++i) {
    s += fmt::format("{}{:.5g}", i ? ", " : "", camera.distortion[i]);
  }
  s += fmt::format("]; with the focal length held lower / higher: rms {:.3f} / {:.3f} px",
                   rms_focal_lower_px, rms_focal_higher_px);
  if (k3_tested) {
    s += fmt::format(
        "; k3 {} (rms {:.4f} px without, {:.4f} px with: BIC gain {:.1f}; fitted on the inner "
        "corners, the outermost {:.0f} % predicted at {:.2f} px rms without, {:.2f} px with; the "
        "two fits put the image corners {:.1f} px apart)",
        k3_kept ? "fitted" : "left out", rms_without_k3_px, rms_with_k3_px, k3_bic_gain,
        100 * kK3HoldOutShare, k3_outer_rms_without_px, k3_outer_rms_with_px, k3_corner_shift_px);
  }
  return s;
}

namespace {  // The stages of CalibrateFromViews.

// Reports every view and checks them; returns the views with the board, *size their image size.
std::vector<int> CheckViews(const std::vector<BoardView>& views, const IntrinsicsOptions& options,
                            IntrinsicsResult* out, cv::Size* size_out) {
  IntrinsicsResult& result = *out;
  std::vector<int> found;
  cv::Size& size = *size_out;
  for (size_t i = 0; i < views.size(); ++i) {
    ViewReport rep;
    rep.name = views[i].name;
    rep.board_found = !views[i].image_points.empty();
    rep.num_corners = static_cast<int>(views[i].image_points.size());
    FV_REQUIRE(views[i].image_points.size() == views[i].object_points.size(),
               "view '{}': {} image points but {} board points", views[i].name,
               views[i].image_points.size(), views[i].object_points.size());
    if (rep.board_found) {
      FV_REQUIRE(rep.num_corners >= 4, "view '{}': {} corners; a view needs at least 4",
                 views[i].name, rep.num_corners);
      if (found.empty()) size = views[i].image_size;
      FV_REQUIRE(views[i].image_size == size,
                 "image '{}' is {}x{} but the first view with the board is {}x{}", views[i].name,
                 views[i].image_size.width, views[i].image_size.height, size.width, size.height);
      found.push_back(static_cast<int>(i));
    }
    result.views.push_back(rep);
  }
  result.num_found = static_cast<int>(found.size());
  FV_REQUIRE(!found.empty(), "no {} found in any of the {} images", options.board.Describe(),
             views.size());
  FV_REQUIRE(result.num_found >= options.min_views,
             "the {} was found in only {} of {} images; at least {} views are needed",
             options.board.Describe(), result.num_found, views.size(), options.min_views);

  return found;
}

// What calibrateCamera gives on the used views.
struct CvFit {
  std::vector<int> used;
  cv::Mat k, d, std_intr;
  std::vector<cv::Mat> rvecs;
  double rms = 0;
};

// calibrateCamera on the views with the board, dropping the worst view above the outlier
// threshold and fitting again while the budget allows.
CvFit FitDroppingOutliers(const std::vector<BoardView>& views, const std::vector<int>& found,
                          const cv::Size& size, const IntrinsicsOptions& options, int flags,
                          int max_drop, IntrinsicsResult* out) {
  IntrinsicsResult& result = *out;
  CvFit fit;
  std::vector<int>& used = fit.used;
  used = found;
  cv::Mat &k = fit.k, &d = fit.d, &std_intr = fit.std_intr, std_extr, per_view;
  std::vector<cv::Mat>& rvecs = fit.rvecs;
  std::vector<cv::Mat> tvecs;
  double& rms = fit.rms;
  while (true) {
    std::vector<std::vector<cv::Point3f>> obj;
    std::vector<std::vector<cv::Point2f>> img;
    for (int i : used) {
      obj.push_back(views[i].object_points);
      img.push_back(views[i].image_points);
    }
    k = cv::Mat::eye(3, 3, CV_64F);
    d = ZeroDistortionFor(flags);
    rvecs.clear();
    tvecs.clear();
    try {
      rms = cv::calibrateCamera(obj, img, size, k, d, rvecs, tvecs, std_intr, std_extr, per_view,
                                flags, FitCriteria());
    } catch (const cv::Exception& e) {
      Throw("calibration failed on {} views of the {} (degenerate views?): {}", used.size(),
            options.board.Describe(), e.err);
    }
    ++result.fits;
    FV_REQUIRE(std::isfinite(rms), "calibration diverged on {} views", used.size());
    std::vector<double> errs(per_view.begin<double>(), per_view.end<double>());
    const double threshold = std::max(
        options.outlier_factor * util::NearestRankPercentile(errs, 0.5), options.outlier_min_px);
    // Drop the worst view above the threshold, one at a time, while the budget allows.
    int worst = -1;
    for (size_t j = 0; j < errs.size(); ++j) {
      if (errs[j] > threshold && (worst < 0 || errs[j] > errs[worst])) worst = static_cast<int>(j);
    }
    const int dropped = result.num_found - static_cast<int>(used.size());
    if (worst < 0 || dropped >= max_drop || static_cast<int>(used.size()) - 1 < options.min_views) {
      for (size_t j = 0; j < used.size(); ++j) {
        result.views[used[j]].used = true;
        result.views[used[j]].rms_px = errs[j];
      }
      break;
    }
    auto& rep = result.views[used[worst]];
    rep.rms_px = errs[worst];
    rep.dropped_because =
        fmt::format("view RMS {:.2f} px > {:.2f} px ({:.1f} x median {:.2f})", errs[worst],
                    threshold, options.outlier_factor, util::NearestRankPercentile(errs, 0.5));
    used.erase(used.begin() + worst);
  }
  result.num_used = static_cast<int>(used.size());
  result.rms_px = rms;
  return fit;
}

// The RMS of the fit on the used views redone with the focal length held at `factor` times the
// estimate (principal point, distortion and poses refitted from the estimate).
double RmsWithFocalScaled(const std::vector<BoardView>& views, const CvFit& fit,
                          const cv::Size& size, int flags, double factor) {
  std::vector<std::vector<cv::Point3f>> obj;
  std::vector<std::vector<cv::Point2f>> img;
  for (int i : fit.used) {
    obj.push_back(views[i].object_points);
    img.push_back(views[i].image_points);
  }
  // From the fit, and when that start fails (a fit that ran off: its principal point outside
  // the image, k3 in the hundreds), from the image's centre without distortion.
  for (const bool from_fit : {true, false}) {
    cv::Mat k = fit.k.clone();
    cv::Mat d = from_fit ? fit.d.clone() : cv::Mat::zeros(fit.d.size(), fit.d.type());
    if (!from_fit) {
      k.at<double>(0, 2) = 0.5 * (size.width - 1);
      k.at<double>(1, 2) = 0.5 * (size.height - 1);
    }
    k.at<double>(0, 0) *= factor;
    k.at<double>(1, 1) *= factor;
    std::vector<cv::Mat> rvecs, tvecs;
    try {
      const double rms = cv::calibrateCamera(
          obj, img, size, k, d, rvecs, tvecs,
          flags | cv::CALIB_USE_INTRINSIC_GUESS | cv::CALIB_FIX_FOCAL_LENGTH, FitCriteria());
      if (std::isfinite(rms)) return rms;
    } catch (const cv::Exception&) {
    }
  }
  return std::numeric_limits<double>::infinity();  // no fit at all: the focal length matters
}

// The lens of a fit: size, intrinsics and the options' number of distortion coefficients.
camera::Camera LensOf(const CvFit& fit, const cv::Size& size, int num_distortion) {
  camera::Camera cam;
  cam.width = size.width;
  cam.height = size.height;
  cam.fx = fit.k.at<double>(0, 0);
  cam.fy = fit.k.at<double>(1, 1);
  cam.cx = fit.k.at<double>(0, 2);
  cam.cy = fit.k.at<double>(1, 2);
  cam.distortion.assign(num_distortion, 0.0);
  for (int i = 0; i < num_distortion && i < static_cast<int>(fit.d.total()); ++i) {
    cam.distortion[i] = fit.d.at<double>(i);
  }
  return cam;
}

cv::Point2f ImageCentre(const cv::Size& size) {
  return {0.5F * static_cast<float>(size.width - 1), 0.5F * static_cast<float>(size.height - 1)};
}

// The distance from the image's centre beyond which the outermost `share` of the used views'
// corners lie.
double OuterRadiusPx(const std::vector<BoardView>& views, const std::vector<int>& used,
                     const cv::Size& size, double share) {
  const cv::Point2f centre = ImageCentre(size);
  std::vector<double> r;
  for (int i : used) {
    for (const auto& p : views[i].image_points) r.push_back(cv::norm(p - centre));
  }
  if (r.empty()) return 0.0;
  const auto nth = r.begin() + static_cast<std::ptrdiff_t>((1.0 - share) * (r.size() - 1));
  std::nth_element(r.begin(), nth, r.end());
  return *nth;
}

// How well a lens model extrapolates: fitted (flags) on the corners of the used views inside
// radius_px of the image's centre (views with at least 8 there), it predicts their corners
// outside, each view's pose from the same fit. RMS in px; infinity when the fit fails or leaves
// nothing to predict.
double OuterPredictionRmsPx(const std::vector<BoardView>& views, const std::vector<int>& used,
                            const cv::Size& size, int flags, double radius_px) {
  const cv::Point2f centre = ImageCentre(size);
  std::vector<std::vector<cv::Point3f>> obj, outer_obj;
  std::vector<std::vector<cv::Point2f>> img, outer_img;
  for (int i : used) {
    const BoardView& v = views[i];
    std::vector<cv::Point3f> o_in, o_out;
    std::vector<cv::Point2f> i_in, i_out;
    for (size_t k = 0; k < v.image_points.size(); ++k) {
      const bool inner = cv::norm(v.image_points[k] - centre) < radius_px;
      (inner ? o_in : o_out).push_back(v.object_points[k]);
      (inner ? i_in : i_out).push_back(v.image_points[k]);
    }
    if (i_in.size() < 8) continue;
    obj.push_back(std::move(o_in));
    img.push_back(std::move(i_in));
    outer_obj.push_back(std::move(o_out));
    outer_img.push_back(std::move(i_out));
  }
  constexpr double kNone = std::numeric_limits<double>::infinity();
  if (obj.size() < 3) return kNone;
  cv::Mat k = cv::Mat::eye(3, 3, CV_64F), d = ZeroDistortionFor(flags);
  std::vector<cv::Mat> rvecs, tvecs;
  try {
    cv::calibrateCamera(obj, img, size, k, d, rvecs, tvecs, flags, FitCriteria());
  } catch (const cv::Exception&) {
    return kNone;
  }
  double sse = 0;
  long long n = 0;
  for (size_t v = 0; v < obj.size(); ++v) {
    if (outer_obj[v].empty()) continue;
    std::vector<cv::Point2f> projected;
    cv::projectPoints(outer_obj[v], rvecs[v], tvecs[v], k, d, projected);
    for (size_t i = 0; i < projected.size(); ++i) {
      const cv::Point2f e = projected[i] - outer_img[v][i];
      sse += e.dot(e);
      ++n;
    }
  }
  return n > 0 && std::isfinite(sse) ? std::sqrt(sse / static_cast<double>(n)) : kNone;
}

// With 5 coefficients: the fit of the other k3 model on the same views (`first` had k3 free
// when first_free, its outliers dropped), compared by the BIC; K3Model::kAuto keeps k3 where its
// gain is over kK3MinBicGain, kFree always. The kept fit's flags in *flags; `first` alone
// (k3_tested false) when the other fit fails.
CvFit CompareK3(const std::vector<BoardView>& views, const cv::Size& size,
                const IntrinsicsOptions& options, CvFit first, bool first_free, int* flags,
                IntrinsicsResult* out) {
  IntrinsicsResult trial = *out;
  const int other_flags = CalibFlags(options, !first_free);
  CvFit other;
  try {
    other = FitDroppingOutliers(views, first.used, size, options, other_flags, 0, &trial);
  } catch (const Error&) {
    return first;  // the other model does not fit these views at all: no comparison
  }
  const CvFit& with = first_free ? first : other;
  const CvFit& without = first_free ? other : first;
  long long points = 0;
  for (int i : first.used) points += static_cast<long long>(views[i].image_points.size());
  // OpenCV's RMS is over the corners' squared distances: the sum of squares is RMS^2 points.
  const double gain =
      util::BicGain(without.rms * without.rms * static_cast<double>(points),
                    with.rms * with.rms * static_cast<double>(points), 2 * points, 1);
  const bool keep_free = options.k3 == K3Model::kFree || gain > kK3MinBicGain;
  // What the choice means beyond the board's reach: both models fitted on the inner corners
  // predict the outermost ones.
  const double radius_px = OuterRadiusPx(views, first.used, size, kK3HoldOutShare);
  const double outer_with =
      OuterPredictionRmsPx(views, first.used, size, CalibFlags(options, true), radius_px);
  const double outer_without =
      OuterPredictionRmsPx(views, first.used, size, CalibFlags(options, false), radius_px);
  const bool keep_other = keep_free != first_free;
  if (keep_other) {
    *out = std::move(trial);  // the views' errors of the kept fit
  } else {
    out->fits = trial.fits;
  }
  IntrinsicsResult& result = *out;
  result.k3_tested = true;
  result.k3_kept = keep_free;
  result.rms_without_k3_px = without.rms;
  result.rms_with_k3_px = with.rms;
  result.k3_bic_gain = gain;
  result.k3_outer_rms_without_px = outer_without;
  result.k3_outer_rms_with_px = outer_with;
  result.k3_corner_shift_px = CornerShiftPx(LensOf(without, size, options.num_distortion),
                                            LensOf(with, size, options.num_distortion));
  if (!keep_other) return first;
  *flags = other_flags;
  return other;
}

// The camera and the standard deviations of its intrinsics from the fit.
void SetCamera(const CvFit& fit, const cv::Size& size, const IntrinsicsOptions& options,
               IntrinsicsResult* out) {
  IntrinsicsResult& result = *out;
  const cv::Mat& std_intr = fit.std_intr;
  camera::Camera& cam = result.camera;
  cam = LensOf(fit, size, options.num_distortion);
  cam.name = options.camera_name;
  cam.rms_px = fit.rms;
  cam.Check("calibrated camera");
  if (std_intr.total() >= 4) {
    result.std_fx_px = std_intr.at<double>(0);
    result.std_fy_px = std_intr.at<double>(1);
    result.std_cx_px = std_intr.at<double>(2);
    result.std_cy_px = std_intr.at<double>(3);
    if (options.fix_aspect_ratio) result.std_fx_px = result.std_fy_px * cam.fx / cam.fy;
  }
}

// Coverage of the image by the corners of the used views, and the spread of board tilts.
CoverageReport Coverage(const std::vector<BoardView>& views, const CvFit& fit, const cv::Size& size,
                        int grid) {
  const std::vector<int>& used = fit.used;
  CoverageReport cov;
  cov.grid = grid;
  cov.corners_per_cell.assign(static_cast<size_t>(cov.grid) * cov.grid, 0);
  const double half_diag = 0.5 * std::hypot(size.width, size.height);
  std::vector<cv::Vec3d> normals;
  for (size_t j = 0; j < used.size(); ++j) {
    for (const auto& p : views[used[j]].image_points) {
      const int c = std::clamp(static_cast<int>(p.x * cov.grid / size.width), 0, cov.grid - 1);
      const int r = std::clamp(static_cast<int>(p.y * cov.grid / size.height), 0, cov.grid - 1);
      ++cov.corners_per_cell[r * cov.grid + c];
      cov.radius_fraction = std::max(
          cov.radius_fraction,
          std::hypot(p.x - 0.5 * (size.width - 1), p.y - 0.5 * (size.height - 1)) / half_diag);
    }
    cv::Mat r;
    cv::Rodrigues(fit.rvecs[j], r);
    normals.emplace_back(r.at<double>(0, 2), r.at<double>(1, 2), r.at<double>(2, 2));
  }
  cov.cell_fraction =
      static_cast<double>(std::count_if(cov.corners_per_cell.begin(), cov.corners_per_cell.end(),
                                        [](int n) { return n > 0; })) /
      cov.corners_per_cell.size();
  for (size_t a = 0; a < normals.size(); ++a) {
    for (size_t b = a + 1; b < normals.size(); ++b) {
      const double c = std::clamp(std::abs(normals[a].dot(normals[b])), 0.0, 1.0);
      cov.tilt_range_deg = std::max(cov.tilt_range_deg, std::acos(c) * 180.0 / M_PI);
    }
  }

  return cov;
}

// Warnings when the views do not pin the model down.
void AddWarnings(const cv::Size& size, const IntrinsicsOptions& options, int max_drop,
                 IntrinsicsResult* out) {
  IntrinsicsResult& result = *out;
  const camera::Camera& cam = result.camera;
  const CoverageReport& cov = result.coverage;
  auto& w = result.warnings;
  if (result.num_used < 8) {
    w.push_back(fmt::format("only {} views: use 10 or more, spread over the image and tilted",
                            result.num_used));
  }
  if (cov.cell_fraction < 0.6) {
    w.push_back(
        fmt::format("corners cover only {:.0f}% of the image cells: distortion outside "
                    "them is extrapolated; show the board near the edges and corners",
                    100 * cov.cell_fraction));
  }
  if (options.num_distortion >= 5 && cov.radius_fraction < 0.75) {
    std::string both;
    if (result.k3_tested) {
      both = fmt::format(" (with and without k3 the image corners lie {:.1f} px apart)",
                         result.k3_corner_shift_px);
    }
    w.push_back(
        fmt::format("corners reach only {:.0f}% of the half diagonal: the higher radial "
                    "terms are not constrained{}",
                    100 * cov.radius_fraction, both));
  }
  if (cov.tilt_range_deg < 15.0) {
    w.push_back(
        fmt::format("board orientations differ by only {:.0f} deg: the focal length is "
                    "poorly constrained; tilt the board by 20-45 deg",
                    cov.tilt_range_deg));
  }
  const double moved_rms = std::min(result.rms_focal_lower_px, result.rms_focal_higher_px);
  if (moved_rms < (1.0 + options.focal_profile_min_gain) * result.rms_px) {
    w.push_back(fmt::format(
        "the views do not pin the focal length down: held {:.0f}% lower or higher it still fits "
        "with RMS {:.3f} px (best {:.3f} px); tilt the board by 20-45 deg",
        100 * (options.focal_profile_factor - 1), moved_rms, result.rms_px));
  }
  if (result.std_fx_px > 0.01 * cam.fx || result.std_fy_px > 0.01 * cam.fy) {
    w.push_back(fmt::format("focal length uncertain: std {:.1f} px ({:.1f}%)", result.std_fx_px,
                            100 * result.std_fx_px / cam.fx));
  }
  if (!(cam.cx >= 0 && cam.cx <= size.width && cam.cy >= 0 && cam.cy <= size.height)) {
    w.push_back(fmt::format(
        "principal point ({:.0f}, {:.0f}) outside the {}x{} image: the fit ran off; show the board "
        "all over the image, tilted by 20-45 deg",
        cam.cx, cam.cy, size.width, size.height));
  }
  if (result.std_cx_px > 0.02 * size.width || result.std_cy_px > 0.02 * size.height) {
    w.push_back(fmt::format("principal point uncertain: std {:.1f}, {:.1f} px", result.std_cx_px,
                            result.std_cy_px));
  }
  const int dropped = result.num_found - result.num_used;
  if (dropped > 0 && dropped >= max_drop) {
    w.push_back(fmt::format("{} views were dropped as outliers (the most allowed)", dropped));
  }
}

// The camera file's notes: board, views used and dropped, model, date.
void AddNotes(const IntrinsicsOptions& options, IntrinsicsResult* out) {
  IntrinsicsResult& result = *out;
  camera::Camera& cam = result.camera;
  std::string used_names, dropped_names;
  for (const auto& v : result.views) {
    if (v.used) used_names += (used_names.empty() ? "" : " ") + v.name;
    if (!v.dropped_because.empty()) dropped_names += (dropped_names.empty() ? "" : " ") + v.name;
  }
  cam.notes["board"] = options.board.Describe();
  cam.notes["views"] = used_names;
  if (!dropped_names.empty()) cam.notes["dropped_views"] = dropped_names;
  cam.notes["num_views"] = std::to_string(result.num_used);
  cam.notes["distortion_model"] = std::to_string(options.num_distortion) + " coefficients";
  if (result.k3_tested) {
    cam.notes["distortion_model"] +=
        options.k3 == K3Model::kFree
            ? fmt::format(", k3 fitted (asked for; BIC gain of fitting it {:.1f})",
                          result.k3_bic_gain)
            : fmt::format(", k3 {} (BIC gain of fitting it {:.1f}; kept by auto over {:.0f})",
                          result.k3_kept ? "fitted" : "zero", result.k3_bic_gain, kK3MinBicGain);
  } else if (options.num_distortion == 5 && options.k3 == K3Model::kZero) {
    cam.notes["distortion_model"] += ", k3 zero";
  }
  cam.notes["date"] = Today();
}

}  // namespace

IntrinsicsResult CalibrateFromViews(const std::vector<BoardView>& views,
                                    const IntrinsicsOptions& options) {
  options.Check();
  IntrinsicsResult result;
  result.num_images = static_cast<int>(views.size());
  cv::Size size;
  const std::vector<int> found = CheckViews(views, options, &result, &size);
  const int max_drop = static_cast<int>(std::floor(options.max_drop_fraction * result.num_found));
  int flags = CalibFlags(options, options.k3 == K3Model::kFree);
  CvFit fit = FitDroppingOutliers(views, found, size, options, flags, max_drop, &result);
  if (options.num_distortion == 5 && options.k3 != K3Model::kZero) {
    fit = CompareK3(views, size, options, std::move(fit), options.k3 == K3Model::kFree, &flags,
                    &result);
  }
  SetCamera(fit, size, options, &result);
  result.rms_focal_lower_px =
      RmsWithFocalScaled(views, fit, size, flags, 1.0 / options.focal_profile_factor);
  result.rms_focal_higher_px =
      RmsWithFocalScaled(views, fit, size, flags, options.focal_profile_factor);
  result.coverage = Coverage(views, fit, size, options.coverage_grid);
  // Views of the board in one orientation (the same image again, a board that never tilts) leave
  // the focal length free (Zhang 2000, sec. 3.1: each view's homography adds two constraints only
  // when its orientation differs): an error, not a camera file with a made-up focal length.
  constexpr double kOneOrientationDeg = 1.0;
  FV_REQUIRE(
      result.num_used < 2 || result.coverage.tilt_range_deg >= kOneOrientationDeg,
      "the {} views show the board ({}) in one orientation (they differ by {:.1f} deg): the focal "
      "length cannot be found; tilt the board by 20-45 deg between views",
      result.num_used, options.board.Describe(), result.coverage.tilt_range_deg);
  AddWarnings(size, options, max_drop, &result);
  AddNotes(options, &result);
  return result;
}

IntrinsicsResult CalibrateIntrinsics(const std::string& images, const IntrinsicsOptions& options) {
  options.Check();
  const ImageSource source(images, options.source);
  std::vector<BoardView> views;
  util::Progress progress("detecting corners", source.size(), "images", options.progress);
  cv::Size first_size;
  for (int i = 0; i < source.size(); ++i) {
    const cv::Mat image = source.Read(i);
    if (i == 0) first_size = image.size();
    FV_REQUIRE(image.size() == first_size, "image '{}' is {}x{} but '{}' is {}x{}", source.name(i),
               image.cols, image.rows, source.name(0), first_size.width, first_size.height);
    views.push_back(DetectBoard(image, options.board, options.detect, source.name(i)));
    progress.Update(i + 1);
  }
  progress.Finish();
  const bool any = std::any_of(views.begin(), views.end(),
                               [](const BoardView& v) { return !v.image_points.empty(); });
  FV_REQUIRE(any, "images '{}': no {} found in any of the {} {} {}", images,
             options.board.Describe(), views.size(), source.what(),
             BoardNotFoundHint(source.Read(0), options.board));
  IntrinsicsResult result = CalibrateFromViews(views, options);
  const LargerBoard larger = LargerChessboardInViews(views, source, options.board);
  if (!larger.size.empty()) {
    result.warnings.push_back(fmt::format(
        "'{}' shows a chessboard of {}, larger than the {}x{} given: a part of it was used, "
        "a different part in different views; give the board's own --cols and --rows",
        larger.view, larger.size, options.board.cols, options.board.rows));
  }
  return result;
}

}  // namespace fv::calib
