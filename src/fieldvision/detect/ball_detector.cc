#include "fieldvision/detect/ball_detector.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/camera/sphere_image.h"
#include "fieldvision/detect/edge_circle.h"
#include "fieldvision/detect/search_area.h"
#include "fieldvision/util/error.h"

namespace fv::detect {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Share of pixels with the ball bit in the disc r < disc_r and in the ring
// ring_r0 <= r < ring_r1 around c.
void DiscShares(const cv::Mat& bgr, const ColourTable& table, uint8_t bit, const Vector2d& c,
                double disc_r, double ring_r0, double ring_r1, double* disc, double* ring) {
  int n_disc = 0, b_disc = 0, n_ring = 0, b_ring = 0;
  // Clamped before the conversion: a diverged fit's centre may lie far outside any int.
  const auto clamped = [](double v, int hi) {
    return static_cast<int>(std::clamp(v, -1.0, static_cast<double>(hi) + 1.0));
  };
  const int x0 = std::max(0, clamped(std::floor(c.x() - ring_r1), bgr.cols));
  const int x1 = std::min(bgr.cols - 1, clamped(std::ceil(c.x() + ring_r1), bgr.cols));
  const int y0 = std::max(0, clamped(std::floor(c.y() - ring_r1), bgr.rows));
  const int y1 = std::min(bgr.rows - 1, clamped(std::ceil(c.y() + ring_r1), bgr.rows));
  for (int y = y0; y <= y1; ++y) {
    const uint8_t* row = bgr.ptr<uint8_t>(y);
    for (int x = x0; x <= x1; ++x) {
      const double d2 = (x - c.x()) * (x - c.x()) + (y - c.y()) * (y - c.y());
      const uint8_t* p = row + 3 * static_cast<ptrdiff_t>(x);
      if (d2 < disc_r * disc_r) {
        ++n_disc;
        b_disc += (table.Classify(p[0], p[1], p[2]) & bit) != 0;
      } else if (d2 >= ring_r0 * ring_r0 && d2 < ring_r1 * ring_r1) {
        ++n_ring;
        b_ring += (table.Classify(p[0], p[1], p[2]) & bit) != 0;
      }
    }
  }
  // Pixels outside the image count as not ball (the disc is then partly invisible).
  const double disc_area = M_PI * disc_r * disc_r;
  *disc = disc_area > 0 ? std::min(1.0, b_disc / disc_area) : 0.0;
  (void)n_disc;
  *ring = n_ring > 0 ? double(b_ring) / n_ring : 0.0;
}

// The [s_lo, s_hi] part of the ray with height in [z_lo, z_hi] and s >= s_min; false if empty.
bool HeightInterval(const geometry::Ray3d& ray, double z_lo, double z_hi, double s_min,
                    double s_max, double* s_lo, double* s_hi) {
  double lo = s_min, hi = s_max;
  const double z0 = ray.origin.z(), dz = ray.direction.z();
  if (std::abs(dz) < 1e-12) {
    if (z0 < z_lo || z0 > z_hi) return false;
  } else {
    double a = (z_lo - z0) / dz, b = (z_hi - z0) / dz;
    if (a > b) std::swap(a, b);
    lo = std::max(lo, a);
    hi = std::min(hi, b);
  }
  *s_lo = lo;
  *s_hi = hi;
  return lo <= hi;
}

// Liang-Barsky: does the xy segment p0 -> p1 meet the rectangle |x| <= hx, |y| <= hy?
bool SegmentMeetsRect(const Vector2d& p0, const Vector2d& p1, double hx, double hy) {
  double t0 = 0, t1 = 1;
  const Vector2d d = p1 - p0;
  const double p[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double q[4] = {p0.x() + hx, hx - p0.x(), p0.y() + hy, hy - p0.y()};
  for (int i = 0; i < 4; ++i) {
    if (std::abs(p[i]) < 1e-15) {
      if (q[i] < 0) return false;
    } else {
      const double t = q[i] / p[i];
      if (p[i] < 0) {
        t0 = std::max(t0, t);
      } else {
        t1 = std::min(t1, t);
      }
    }
  }
  return t0 <= t1;
}

// The first outline check the sub-pixel fit fails ("" when it passes them all).
std::string OutlineProblem(const BallFit& fit, double visible, double leak,
                           const BallDetectorOptions& o) {
  if (fit.inlier_fraction < o.min_inlier_fraction) {
    return fmt::format("outline not round ({:.0f} % on the circle)", 100 * fit.inlier_fraction);
  }
  if (fit.outside_fraction > o.max_outside_fraction) {
    return fmt::format("colour goes on beyond the circle on {:.0f} % of rays",
                       100 * fit.outside_fraction);
  }
  if (fit.inlier_fraction < 0.75 && fit.outside_fraction > o.max_outside_fraction_occluded) {
    return fmt::format("partial outline with colour beyond the circle on {:.0f} % of rays",
                       100 * fit.outside_fraction);
  }
  if (fit.dents > o.max_dents && fit.inlier_fraction < 0.85) {
    return fmt::format("outline has {} dents: not a disc", fit.dents);
  }
  if (fit.rms_px > o.max_fit_rms_px) return fmt::format("outline rms {:.2f} px", fit.rms_px);
  if (visible < o.min_visible_fraction) {
    return fmt::format("disc only {:.0f} % ball-coloured", 100 * visible);
  }
  if (leak > o.max_leak_fraction) {
    return fmt::format("colour extends beyond the circle ({:.0f} %)", 100 * leak);
  }
  return "";
}

// The share of min_contrast and min_hue_contrast a region needs: less on the field.
double LeastContrastFactor(const BallRegion& r, const BallDetectorOptions& o) {
  return r.field_ring >= o.min_field_ring && r.grass_ring >= o.min_grass_ring
             ? o.field_contrast_factor
             : 1.0;
}

// Whether a measured region stands out from its surroundings: by its colour difference
// (min_contrast), by its hue difference alone (min_hue_contrast) or, against a neutral surround,
// by its chroma (min_chroma_contrast), less on the field; or it stands apart from the camera's
// background.
bool StandsOut(const BallRegion& r, const BallDetectorOptions& o) {
  if (r.apart_from_background) return true;
  const double f = LeastContrastFactor(r, o);
  const bool neutral_ring = r.ring_chroma <= o.max_neutral_ring_chroma &&
                            r.ring_lightness >= o.min_neutral_ring_lightness;
  return r.contrast >= f * o.min_contrast || r.hue_contrast >= f * o.min_hue_contrast ||
         (neutral_ring && r.chroma_contrast >= f * o.min_chroma_contrast);
}

// Whether a region that does not stand out (StandsOut) comes near: its colour difference at least
// kNearContrast of what is asked. The background then decides; a person's head or a shirt,
// which move as a ball does, are mostly farther from the ball's colour (PETS 2009, orange: 13
// heads accepted on the background alone at any contrast).
bool NearlyStandsOut(const BallRegion& r, const BallDetectorOptions& o) {
  constexpr double kNearContrast = 0.75;
  BallRegion scaled = r;
  scaled.contrast /= kNearContrast;
  scaled.hue_contrast /= kNearContrast;
  scaled.chroma_contrast /= kNearContrast;
  return StandsOut(scaled, o);
}

// The first region check the candidate fails ("" when it passes them all); with
// `shape_only` the colour checks (leak, contrast) are left out.
std::string RegionProblem(const BallRegion& r, const BallDetectorOptions& o, double min_arc_cover,
                          bool shape_only = false) {
  if (r.arc_cover < min_arc_cover) {
    return fmt::format("region outline not round ({:.0f} % of the circle)", 100 * r.arc_cover);
  }
  if (r.outside > o.max_region_outside) {
    return fmt::format("region outline sticks out of its circle ({:.0f} %)", 100 * r.outside);
  }
  if (r.extent > o.max_region_extent) {
    return fmt::format("region has corners ({:.2f} radii out)", r.extent);
  }
  if (r.fill < o.min_region_fill) {
    return fmt::format("region fills only {:.0f} % of its circle", 100 * r.fill);
  }
  if (r.spill > o.max_region_spill) {
    return fmt::format("region spills beyond its circle ({:.0f} %)", 100 * r.spill);
  }
  if (shape_only) return "";
  if (r.leak > o.max_ring_leak) {
    return fmt::format("ball colour around the circle ({:.0f} % of a ring)", 100 * r.leak);
  }
  if (!StandsOut(r, o)) {
    return fmt::format("too little contrast with the surroundings (Delta E {:.0f})", r.contrast);
  }
  return "";
}

}  // namespace

double BallDetector::SmallestPlausibleRadius(double expected_min_px) const {
  return expected_min_px * (1 - options_.size_tolerance) - 0.5;
}

std::string BallDetector::SizeProblem(const Vector2d& centre, double radius,
                                      double* size_factor) const {
  const BallDetectorOptions& o = options_;
  *size_factor = 1.0;
  if (radius < o.min_radius_px || radius > o.max_radius_px) {
    return fmt::format(
        "radius outside the allowed range ({:.1f} px; --min-radius {}, "
        "--max-radius {})",
        radius, o.min_radius_px, o.max_radius_px);
  }
  double exp_min = 0, exp_max = 0;
  if (!ExpectedRadius(centre, &exp_min, &exp_max)) return "";
  const double lo = SmallestPlausibleRadius(exp_min);
  const double hi = exp_max * (1 + o.size_tolerance) + 0.5;
  if (radius < lo) return fmt::format("too small for a ball here ({:.1f} < {:.1f} px)", radius, lo);
  if (radius > hi) return fmt::format("too large for a ball here ({:.1f} > {:.1f} px)", radius, hi);
  if (exp_min > 0) {
    // Prefer sizes near the ball on the ground.
    const double f = std::exp(-0.5 * std::pow(std::log(radius / exp_min) / 0.3, 2));
    *size_factor = 0.5 + 0.5 * f;
  }
  return "";
}

void BallDetectorOptions::Check() const {
  CheckPositive(diameter_m, "diameter_m");
  CheckFinite(diameter_m, "diameter_m");
  FV_REQUIRE(!colour.empty(), "colour must name a preset or a colour file");
  FV_REQUIRE(lut_bits >= 5 && lut_bits <= 8, "lut_bits must be 5..8 (got {})", lut_bits);
  FV_REQUIRE(scan_step_px >= 1 && scan_step_px <= 16, "scan_step_px must be 1..16 (got {})",
             scan_step_px);
  FV_REQUIRE(min_samples >= 1, "min_samples must be >= 1 (got {})", min_samples);
  CheckPositive(min_radius_px, "min_radius_px");
  FV_REQUIRE(std::isfinite(max_radius_px) && max_radius_px > min_radius_px,
             "max_radius_px must be finite and > min_radius_px (got {})", max_radius_px);
  FV_REQUIRE(diameter_m < 2.0, "diameter_m must be below 2 m (got {})", diameter_m);
  CheckInRange(min_fill_ratio, 0.0, 1.0, "min_fill_ratio");
  FV_REQUIRE(max_aspect_ratio >= 1.0, "max_aspect_ratio must be >= 1 (got {})", max_aspect_ratio);
  CheckInRange(min_inlier_fraction, 0.0, 1.0, "min_inlier_fraction");
  CheckPositive(max_fit_rms_px, "max_fit_rms_px");
  CheckInRange(min_visible_fraction, 0.0, 1.0, "min_visible_fraction");
  CheckInRange(max_leak_fraction, 0.0, 1.0, "max_leak_fraction");
  CheckInRange(max_outside_fraction, 0.0, 1.0, "max_outside_fraction");
  CheckInRange(max_outside_fraction_occluded, 0.0, 1.0, "max_outside_fraction_occluded");
  CheckInRange(size_tolerance, 0.0, 10.0, "size_tolerance");
  CheckPositive(max_height_m, "max_height_m");
  CheckNonNegative(min_distance_m, "min_distance_m");
  CheckNonNegative(field_margin_m, "field_margin_m");
  FV_REQUIRE(max_dents >= 0, "max_dents must be >= 0 (got {})", max_dents);
  FV_REQUIRE(max_refine >= 1, "max_refine must be >= 1 (got {})", max_refine);
  FV_REQUIRE(weak_min_inlier_fraction >= 0 && weak_min_inlier_fraction <= 1,
             "weak_min_inlier_fraction must be in [0, 1] (got {})", weak_min_inlier_fraction);
  CheckInRange(guided_radius_change, 0.0, 1.0, "guided_radius_change");
  CheckInRange(guided_max_shift_radii, 0.0, 10.0, "guided_max_shift_radii");
  CheckInRange(min_arc_cover, 0.0, 1.0, "min_arc_cover");
  CheckInRange(unposed_min_arc_cover, 0.0, 1.0, "unposed_min_arc_cover");
  CheckInRange(min_region_fill, 0.0, 1.0, "min_region_fill");
  CheckNonNegative(max_region_spill, "max_region_spill");
  CheckInRange(max_ring_leak, 0.0, 1.0, "max_ring_leak");
  CheckNonNegative(min_contrast, "min_contrast");
  CheckNonNegative(min_hue_contrast, "min_hue_contrast");
  CheckNonNegative(min_chroma_contrast, "min_chroma_contrast");
  CheckNonNegative(max_neutral_ring_chroma, "max_neutral_ring_chroma");
  CheckNonNegative(min_neutral_ring_lightness, "min_neutral_ring_lightness");
  CheckInRange(min_field_ring, 0.0, 1.0, "min_field_ring");
  CheckInRange(min_grass_ring, 0.0, 1.0, "min_grass_ring");
  CheckInRange(field_contrast_factor, 0.0, 1.0, "field_contrast_factor");
  CheckInRange(max_region_outside, 0.0, 1.0, "max_region_outside");
  FV_REQUIRE(max_region_extent >= 1.0, "max_region_extent must be >= 1 (got {})",
             max_region_extent);
  CheckInRange(off_field_min_score, 0.0, 1.0, "off_field_min_score");
  CheckInRange(off_field_min_visible, 0.0, 1.0, "off_field_min_visible");
  CheckNonNegative(off_field_min_radius_px, "off_field_min_radius_px");
  CheckNonNegative(min_lit_field_ratio, "min_lit_field_ratio");
  field_brightness.Check();
  field_boundary.Check();
  CheckInRange(grow_hue_deg, 0.0, 60.0, "grow_hue_deg");
  CheckInRange(grow_factor, 0.0, 1.0, "grow_factor");
  region.Check();
  fit.Check();
  small.Check();
  small_field.Check();
}

int BallDetectionResult::accepted() const {
  return static_cast<int>(std::count_if(candidates.begin(), candidates.end(),
                                        [](const BallCandidate& c) { return c.accepted; }));
}

std::string BallDetectionResult::Summary() const {
  return fmt::format("{} samples, {} runs, {} blobs, {} refined, {} candidates, {} accepted",
                     samples, runs, blobs, refined, candidates.size(), accepted());
}

BallDetector::BallDetector(const BallDetectorOptions& options, const camera::Camera* camera,
                           const field::FieldModel* field)
    : options_(options), camera_(camera), field_(field) {
  options_.Check();
  Init(LoadColourSpec(options_.colour));
}

BallDetector::BallDetector(const BallDetectorOptions& options, const ColourSpec& colour,
                           const camera::Camera* camera, const field::FieldModel* field)
    : options_(options), camera_(camera), field_(field) {
  options_.Check();
  Init(colour);
}

void BallDetector::Init(const ColourSpec& colour) {
  colour.Check("colour spec");
  if (camera_ != nullptr) camera_->Check();
  // The widened ball class the regions grow through: a class of the same table when it fits.
  table_ = ColourTable::Shared(
      options_.use_region ? WithWidenedBall(colour, options_.grow_hue_deg, options_.grow_factor)
                          : colour,
      options_.lut_bits);
  ball_bit_ = table_->BallBit();
  field_bit_ = table_->ClassBitOrZero("field");
  if (options_.use_region) {
    grow_bit_ = table_->ClassBitOrZero(WidenedBallClass(colour));
    if (grow_bit_ != 0) {
      grow_table_ = table_;
    } else {  // no room in the spec: a table of its own
      grow_table_ = ColourTable::Shared(
          WidenedBallSpec(colour, options_.grow_hue_deg, options_.grow_factor), options_.lut_bits);
      grow_bit_ = grow_table_->BallBit();
    }
  }
  if (posed() && field_ != nullptr && options_.use_field_mask) {
    field_mask_ = FieldMask(*camera_, *field_, options_.field_margin_m, options_.max_height_m);
  }
  small_balls_ = SmallBallsPossible();
  const bool dark_ball =
      options_.colour == "black" || options_.colour == "blue" || options_.colour == "green";
  min_arc_cover_ = posed() ? options_.min_arc_cover : options_.unposed_min_arc_cover;
  lit_check_ = options_.min_lit_field_ratio > 0 && !dark_ball && !posed();
}

bool BallDetector::SmallBallsPossible() const {
  const SmallBallOptions& o = options_.small;
  if (o.mode != "auto") return o.mode == "on";
  if (!posed()) return true;  // on the field (RejectSmallOffField)
  // Anywhere on a 32 x 24 grid (inside the field mask) where the ball may look that small.
  for (int j = 0; j < 24; ++j) {
    for (int i = 0; i < 32; ++i) {
      const Vector2d uv((i + 0.5) * camera_->width / 32.0, (j + 0.5) * camera_->height / 24.0);
      if (!field_mask_.empty() && field_mask_.at<uint8_t>(int(uv.y()), int(uv.x())) == 0) continue;
      double lo = 0, hi = 0;
      if (ExpectedRadius(uv, &lo, &hi) && SmallestPlausibleRadius(lo) <= o.max_radius_px) {
        return true;
      }
    }
  }
  return false;
}

bool BallDetector::ExpectedRadius(const Vector2d& uv, double* min_px, double* max_px) const {
  if (!posed()) return false;
  const auto ray = camera_->RayFromPixel(uv);
  if (!ray) return false;
  const double r_m = 0.5 * options_.diameter_m;
  double s_lo, s_hi;
  if (!HeightInterval(*ray, r_m, options_.max_height_m, options_.min_distance_m, 1e6, &s_lo,
                      &s_hi)) {
    return false;
  }
  // Image radius of the ball at distance s along the ray.
  auto radius_at = [&](double s) {
    const Vector3d p = ray->At(s);
    const std::optional<double> r_px = camera::SphereRadiusPx(*camera_, p, r_m);
    return r_px ? *r_px : r_m / camera_->PixelFootprintM(p);
  };
  *max_px = radius_at(s_lo);
  *min_px = s_hi >= 1e5 ? 0.0 : radius_at(s_hi);
  return true;
}

std::vector<BallCandidate> BallDetector::Detect(const cv::Mat& bgr, const cv::Rect& region) const {
  return DetectWithSummary(bgr, region).candidates;
}

namespace {

// What a comparison with the background tells of a candidate: apart from it when it says so, and
// the disc's changed share whenever it was read (the fusion's still-vs-new rule).
void TakeEvidence(const BackgroundEvidence& evidence, BallCandidate* c) {
  c->apart_from_background = c->apart_from_background || evidence.apart;
  if (evidence.measured) c->background_change = evidence.disc_share;
}

// Disc-like blobs first (a printed or partly hidden ball may be a few of them), then larger.
std::vector<const Blob*> DiscLikeFirst(const BlobScanResult& blobs, double max_aspect_ratio) {
  std::vector<const Blob*> order;
  order.reserve(blobs.blobs.size());
  for (const Blob& b : blobs.blobs) order.push_back(&b);
  std::stable_sort(order.begin(), order.end(), [&](const Blob* a, const Blob* b) {
    return (a->aspect_ratio() <= max_aspect_ratio) > (b->aspect_ratio() <= max_aspect_ratio);
  });
  return order;
}

// The fit reads up to about two radii beyond a blob: blobs nearer than that to an edge of the
// region that is not the image's own edge cannot be fitted from the region's pixels.
bool FitsInRegion(const Blob& b, const cv::Rect& roi, const cv::Size& image) {
  if (roi == cv::Rect(0, 0, image.width, image.height)) return true;
  const int m = static_cast<int>(std::ceil(std::max(b.width_px(), b.height_px()))) + 4;
  return (roi.x == 0 || b.x_min - m >= roi.x) && (roi.y == 0 || b.y_min - m >= roi.y) &&
         (roi.x + roi.width == image.width || b.x_max + m < roi.x + roi.width) &&
         (roi.y + roi.height == image.height || b.y_max + m < roi.y + roi.height);
}

// Best first; one ball, one candidate: a later accepted candidate on a better one is a duplicate.
void RankAndDropDuplicates(std::vector<BallCandidate>* candidates) {
  auto better = [](const BallCandidate& a, const BallCandidate& b) {
    if (a.accepted != b.accepted) return a.accepted;
    return a.score > b.score;
  };
  std::stable_sort(candidates->begin(), candidates->end(), better);
  for (size_t i = 0; i < candidates->size(); ++i) {
    BallCandidate& c = (*candidates)[i];
    if (!c.accepted) continue;
    for (size_t j = 0; j < i; ++j) {
      const BallCandidate& b = (*candidates)[j];
      if (b.accepted && (b.centre_px - c.centre_px).norm() < std::max(b.radius_px, 2.0)) {
        c.accepted = false;
        c.reason = "duplicate";
        break;
      }
    }
  }
  std::stable_sort(candidates->begin(), candidates->end(), better);
}

}  // namespace

bool BallDetector::MeasuredRegions::Holds(const BallRegion& region) const {
  for (size_t i = 0; i < centres.size(); ++i) {
    if ((centres[i] - region.centre_px).norm() < std::max(0.5 * radii[i], 1.0)) return true;
  }
  return false;
}

BallDetectionResult BallDetector::DetectWithSummary(const cv::Mat& bgr,
                                                    const cv::Rect& region) const {
  FV_REQUIRE(!bgr.empty(), "ball detector: the frame is empty");
  FV_REQUIRE(bgr.type() == CV_8UC3, "ball detector: the frame must be 8-bit BGR (got type {})",
             bgr.type());
  if (camera_ != nullptr) {
    FV_REQUIRE(bgr.cols == camera_->width && bgr.rows == camera_->height,
               "frame is {}x{} but camera '{}' is {}x{}", bgr.cols, bgr.rows, camera_->name,
               camera_->width, camera_->height);
  }
  const BallDetectorOptions& o = options_;
  ScanOptions scan;
  scan.step_px = o.scan_step_px;
  scan.min_samples = o.min_samples;
  const cv::Rect roi = SearchArea(bgr.size(), region);
  const BlobScanResult blobs = ScanBlobs(bgr, *table_, ball_bit_, scan, field_mask_, roi);
  BallDetectionResult result;
  result.blobs = static_cast<int>(blobs.blobs.size());
  result.runs = blobs.runs;
  result.samples = blobs.samples;
  MeasuredRegions measured;
  std::vector<const Blob*> order = DiscLikeFirst(blobs, o.max_aspect_ratio);
  if (static_cast<int>(order.size()) > o.max_refine) ChangedFirst(bgr, roi, &order);
  for (const Blob* blob : order) {
    if (!FitsInRegion(*blob, roi, bgr.size())) continue;
    std::optional<BallCandidate> cand = EvaluateBlob(bgr, *blob, roi, &measured, &result.refined);
    if (cand) result.candidates.push_back(std::move(*cand));
  }
  AddApartInRejected(bgr, roi, &result.candidates);
  std::optional<FieldBoundary> boundary;
  RejectOffField(bgr, roi, &boundary, &result.candidates);
  // Every check of the blobs' candidates first: small balls are looked for when none is left.
  RejectDarkerThanField(bgr, roi, &result.candidates);
  // The small-ball stage runs when the colour checks accepted nothing (a candidate accepted only
  // by the background does not stop it: a far ball may be the real one).
  const bool colour_accepted =
      std::any_of(result.candidates.begin(), result.candidates.end(),
                  [](const BallCandidate& c) { return c.accepted && !c.apart_from_background; });
  if (small_balls_ && !colour_accepted) {
    AddSmallBalls(bgr, roi, &result);
    RejectOffField(bgr, roi, &boundary, &result.candidates);
    RejectSmallOffField(bgr, roi, &result.candidates);
    RejectDarkerThanField(bgr, roi, &result.candidates);
  }
  RankAndDropDuplicates(&result.candidates);
  OnFieldFirst(bgr, roi, &boundary, &result.candidates);
  ApartFirst(bgr, roi, &result.candidates);
  return result;
}

namespace {

// Up to `most` of `rejected` whose disc differs from the background, the largest changed area
// (disc share x radius^2) first: a ball merged with a board or block of its colour, not the
// stands' still blocks, which are larger.
std::vector<const BallCandidate*> MostChanged(const cv::Mat& bgr, const cv::Rect& roi,
                                              const Background& background,
                                              const std::vector<const BallCandidate*>& rejected,
                                              int most) {
  std::vector<std::pair<double, const BallCandidate*>> changed;
  for (const BallCandidate* c : rejected) {
    const BackgroundEvidence e = background.Compare(bgr, c->centre_px, c->radius_px, roi);
    const double area = e.measured ? e.disc_share * c->radius_px * c->radius_px : 0.0;
    if (area > 0) changed.emplace_back(area, c);
  }
  std::stable_sort(changed.begin(), changed.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<const BallCandidate*> out;
  for (size_t i = 0; i < changed.size() && static_cast<int>(i) < most; ++i) {
    out.push_back(changed[i].second);
  }
  return out;
}

}  // namespace

void BallDetector::AddApartInRejected(const cv::Mat& bgr, const cv::Rect& roi,
                                      std::vector<BallCandidate>* candidates) const {
  if (!background_) return;
  constexpr int kMaxLooks = 4;  // rejected regions looked into per frame
  // The region at least as large as its changed part (a ball with what it merged with, or a ball
  // whose own region failed its shape checks); 1.5 (well inside) accepted 4 fewer of the 192
  // views of the low-sun statics, seeds 1-3, with the same 3D errors.
  constexpr double kMergedRatio = 1.0;
  constexpr double kMergedSigmaRadii = 0.1;  // low-sun statics 0.05 / 0.1 / 0.2 alike
  std::vector<const BallCandidate*> rejected;
  for (const BallCandidate& c : *candidates) {
    if (!c.accepted && c.radius_px >= options_.min_radius_px) rejected.push_back(&c);
  }
  if (rejected.empty()) return;
  const Background* background = background_();
  if (background == nullptr) return;
  rejected = MostChanged(bgr, roi, *background, rejected, kMaxLooks);
  std::vector<BallCandidate> found;
  for (const BallCandidate* c : rejected) {
    const double reach = 1.5 * c->radius_px + 2;
    const cv::Rect box(static_cast<int>(std::floor(c->centre_px.x() - reach)),
                       static_cast<int>(std::floor(c->centre_px.y() - reach)),
                       static_cast<int>(std::ceil(2 * reach)) + 1,
                       static_cast<int>(std::ceil(2 * reach)) + 1);
    const std::optional<Background::Circle> disc = background->ChangedDisc(bgr, box, roi);
    // What changed must lie within the region: a changed part larger than the region (a blurred
    // ball's streak, a person) is the tracker's guided fit's to find, seeded where the ball is
    // expected.
    if (!disc || disc->radius_px < options_.min_radius_px ||
        c->radius_px < kMergedRatio * disc->radius_px) {
      continue;
    }
    std::optional<BallCandidate> fit = FitAt(bgr, roi, disc->centre_px, disc->radius_px);
    if (!fit) continue;
    const BackgroundEvidence evidence =
        background->Compare(bgr, fit->centre_px, fit->radius_px, roi);
    if (!evidence.apart) continue;
    TakeEvidence(evidence, &*fit);
    const auto same = [&](const BallCandidate& b) {
      return (b.centre_px - fit->centre_px).norm() < std::max(b.radius_px, 2.0);
    };
    if (std::any_of(candidates->begin(), candidates->end(),
                    [&](const BallCandidate& b) { return b.accepted && same(b); }) ||
        std::any_of(found.begin(), found.end(), same)) {
      continue;
    }
    fit->guided = false;
    // Fitted beside a neighbour of its colour: part of its outline is that neighbour's.
    fit->sigma_px = std::max(fit->sigma_px, kMergedSigmaRadii * fit->radius_px);
    found.push_back(*fit);
  }
  candidates->insert(candidates->end(), found.begin(), found.end());
}

void BallDetector::ChangedFirst(const cv::Mat& bgr, const cv::Rect& roi,
                                std::vector<const Blob*>* order) const {
  if (!background_) return;
  const Background* background = background_();
  if (background == nullptr) return;
  constexpr double kChangedShare = 0.5;
  // A disc of 2 reduced pixels at least: a smaller one reads too few of them to say anything (a
  // 1.5 px yellow patch of a printed, shaded 5 px ball never counted as changed).
  const double min_radius_px = 2.0 * background->scale();
  std::stable_partition(order->begin(), order->end(), [&](const Blob* b) {
    const double radius = std::max(0.5 * std::max(b->width_px(), b->height_px()), min_radius_px);
    return background->Compare(bgr, b->centroid_px(), radius, roi).disc_share >= kChangedShare;
  });
}

void BallDetector::ApartFirst(const cv::Mat& bgr, const cv::Rect& roi,
                              std::vector<BallCandidate>* candidates) const {
  if (!background_) return;
  const auto accepted_end = std::find_if(candidates->begin(), candidates->end(),
                                         [](const BallCandidate& c) { return !c.accepted; });
  if (accepted_end - candidates->begin() < 2) return;
  const Background* background = background_();
  if (background == nullptr) return;
  for (auto it = candidates->begin(); it != accepted_end; ++it) {
    const BackgroundEvidence evidence = background->Compare(bgr, it->centre_px, it->radius_px, roi);
    TakeEvidence(evidence, &*it);
  }
  // Apart from the background counts as a quarter more score: it reorders near equals, it does
  // not put a faint candidate before a clear one (a passer-by's head before a still ball: PETS
  // 2009 as Motion-JPEG, orange, 300 frames: with twice the score 6 of 7 such heads went first).
  constexpr double kApartBonus = 1.25;
  std::stable_sort(candidates->begin(), accepted_end,
                   [&](const BallCandidate& a, const BallCandidate& b) {
                     return a.score * (a.apart_from_background ? kApartBonus : 1.0) >
                            b.score * (b.apart_from_background ? kApartBonus : 1.0);
                   });
}

void BallDetector::OnFieldFirst(const cv::Mat& bgr, const cv::Rect& roi,
                                std::optional<FieldBoundary>* boundary,
                                std::vector<BallCandidate>* candidates) const {
  if (posed() || options_.off_field_min_score <= 0) return;
  const auto accepted_end = std::find_if(candidates->begin(), candidates->end(),
                                         [](const BallCandidate& c) { return !c.accepted; });
  if (accepted_end - candidates->begin() < 2) return;
  if (!boundary->has_value()) *boundary = OffFieldBoundary(bgr, roi);
  std::stable_partition(candidates->begin(), accepted_end, [&](const BallCandidate& c) {
    return !(*boundary)->DiscAbove(c.centre_px.x(), c.centre_px.y(), c.radius_px);
  });
}

FieldBoundary BallDetector::OffFieldBoundary(const cv::Mat& bgr, const cv::Rect& region) const {
  if (posed() || options_.off_field_min_score <= 0) {
    return {};
  }
  return FindFieldBoundary(bgr, *table_, field_bit_, options_.field_boundary, region);
}

void BallDetector::RejectOffField(const cv::Mat& bgr, const cv::Rect& roi,
                                  std::optional<FieldBoundary>* boundary,
                                  std::vector<BallCandidate>* candidates) const {
  const BallDetectorOptions& o = options_;
  const double min_score = o.off_field_min_score;
  for (BallCandidate& c : *candidates) {
    const bool whole_disc = c.region_ok && c.visible_fraction >= o.off_field_min_visible &&
                            c.radius_px >= o.off_field_min_radius_px;
    if (!c.accepted || c.score >= min_score || whole_disc) continue;
    if (!boundary->has_value()) *boundary = OffFieldBoundary(bgr, roi);
    if (!(*boundary)->DiscAbove(c.centre_px.x(), c.centre_px.y(), c.radius_px)) continue;
    c.accepted = false;
    c.reason = fmt::format(
        "above the field's edge ({:.0f} px), score {:.2f} < {:.2f}, not a whole disc",
        (*boundary)->Above(c.centre_px.x(), c.centre_px.y() + c.radius_px), c.score, min_score);
  }
}

double BallDetector::FieldShare(const cv::Mat& bgr, const cv::Rect& roi,
                                const Eigen::Vector2d& centre_px, double radius_px, double enough,
                                ImageFieldCache* image_field) const {
  const FieldSurroundOptions& o = options_.small_field;
  const double share = field_bit_ != 0 ? FieldShareAround(bgr, *table_, field_bit_, nullptr,
                                                          centre_px, radius_px, o, roi)
                                       : -1.0;
  if (share >= enough) return share;
  // The image's own field colour only where the field class finds too little (a carpet the
  // class misses).
  if (!*image_field) {
    *image_field = FindImageFieldColour(bgr, roi, options_.field_brightness.image_field);
  }
  const std::optional<ImageFieldColour>& found = **image_field;
  if (!found) return share;  // -1 without a field class: no field to tell
  return FieldShareAround(bgr, *table_, field_bit_, &*found, centre_px, radius_px, o, roi);
}

void BallDetector::RejectSmallOffField(const cv::Mat& bgr, const cv::Rect& roi,
                                       std::vector<BallCandidate>* candidates) const {
  const double min_share = options_.small_field.min_share;
  if (min_share <= 0 || posed()) return;
  ImageFieldCache image_field;
  for (BallCandidate& c : *candidates) {
    if (!c.accepted || !c.small) continue;
    const double share = FieldShare(bgr, roi, c.centre_px, c.radius_px, min_share, &image_field);
    if (share < 0 || share >= min_share) continue;
    c.accepted = false;
    c.reason = fmt::format("a small spot off the field ({:.0f} % of its ring field)", 100 * share);
  }
}

void BallDetector::RejectDarkerThanField(const cv::Mat& bgr, const cv::Rect& roi,
                                         std::vector<BallCandidate>* candidates) const {
  if (!lit_check_) return;
  const double ratio = options_.min_lit_field_ratio;
  std::optional<double> field_value;  // measured at the first accepted candidate
  for (BallCandidate& c : *candidates) {
    if (!c.accepted) continue;
    if (!field_value) {
      field_value = FieldValue(bgr, *table_, field_bit_, options_.field_brightness, roi);
    }
    if (*field_value < 0) return;  // too little field to tell
    const double lit = LitValue(bgr, c.centre_px, c.radius_px, options_.field_brightness);
    if (lit < 0 || lit >= ratio * *field_value) continue;
    c.accepted = false;
    c.reason = fmt::format("darker than the field (lit part V {:.0f} < {:.2f} x field V {:.0f})",
                           lit, ratio, *field_value);
  }
}

std::optional<BallCandidate> BallDetector::EvaluateBlob(const cv::Mat& bgr, const Blob& blob,
                                                        const cv::Rect& roi,
                                                        MeasuredRegions* measured,
                                                        int* refined) const {
  const BallDetectorOptions& o = options_;
  BallCandidate cand;
  cand.centre_px = Vector2d(0.5 * (blob.x_min + blob.x_max), 0.5 * (blob.y_min + blob.y_max));
  cand.radius_px = 0.25 * (blob.width_px() + blob.height_px());
  cand.sigma_px = 0.5 * blob.step_px;
  auto reject = [&](std::string why) {
    cand.accepted = false;
    cand.reason = std::move(why);
    return cand;
  };
  const double rough_r = 0.5 * std::max(blob.width_px(), blob.height_px());
  if (rough_r > 1.5 * o.max_radius_px) return reject("blob size");
  if (*refined >= o.max_refine) return reject("not refined (max_refine)");
  // 1. The region check: the blob with its neighbouring fragments, holes filled.
  BallRegion region;
  if (o.use_region) {
    const int half = blob.step_px / 2 + 1;
    const cv::Rect seed(blob.x_min - half, blob.y_min - half,
                        blob.x_max - blob.x_min + 2 * half + 1,
                        blob.y_max - blob.y_min + 2 * half + 1);
    region = AnalyseBallRegion(bgr, *table_, ball_bit_, seed, roi, o.region, grow_table_.get(),
                               grow_bit_);
    if (region.ok) {
      if (measured->Holds(region)) return std::nullopt;  // a fragment of a region measured
      measured->centres.push_back(region.centre_px);
      measured->radii.push_back(region.radius_px);
      cand.region_ok = true;
      cand.arc_cover = region.arc_cover;
      cand.fill = region.fill;
      cand.spill = region.spill;
      cand.leak = region.leak;
      cand.contrast = region.contrast;
      cand.hue_contrast = region.hue_contrast;
      cand.chroma_contrast = region.chroma_contrast;
      cand.region_outside = region.outside;
      cand.region_extent = region.extent;
      cand.centre_px = region.centre_px;
      cand.radius_px = region.radius_px;
      cand.sigma_px = region.sigma_px;
    }
  }
  if (!region.ok) {
    if (blob.aspect_ratio() > o.max_aspect_ratio) return reject("blob aspect ratio");
    if (blob.samples >= 6 && blob.fill_ratio() < o.min_fill_ratio) {
      return reject("blob fill ratio");
    }
  }
  ++*refined;
  // 2. The sub-pixel outline fit, seeded by the region when there is one.
  const Vector2d seed_c = region.ok ? region.centre_px : blob.centroid_px();
  const double seed_r = region.ok ? region.radius_px : rough_r;
  BallFit fit = seed_r >= 0.5 * o.min_radius_px
                    ? FitBall(bgr, *table_, ball_bit_, seed_c, seed_r, camera_, o.fit)
                    : BallFit{};
  if (region.ok && !fit.ok && rough_r >= 0.5 * o.min_radius_px) {
    // A region that took in a neighbour seeds badly: the blob itself may still fit.
    fit = FitBall(bgr, *table_, ball_bit_, blob.centroid_px(), rough_r, camera_, o.fit);
  }
  std::string fit_why;  // why the precise path fails
  double visible = 0.0, leak = 1.0;
  if (!fit.ok) {
    fit_why = fit.failure.empty() ? "too small to fit" : fit.failure;
  } else {
    DiscShares(bgr, *table_, ball_bit_, fit.centre_px, std::max(fit.radius_px - 0.7, 0.5),
               fit.radius_px + 1.5, fit.radius_px + 3.5, &visible, &leak);
    fit_why = OutlineProblem(fit, visible, leak, o);
  }
  BallCandidate if_apart = cand;  // as Decide finds it
  Decide(region, fit, fit_why, visible, leak, &cand);
  if (!cand.accepted && region.ok && background_ && !StandsOut(region, o) &&
      NearlyStandsOut(region, o)) {
    // Rejected, with a region that does not stand out by colour: if standing out would have
    // accepted it, the background decides.
    BallRegion apart = region;
    apart.apart_from_background = true;
    Decide(apart, fit, fit_why, visible, leak, &if_apart);
    const Background* background = if_apart.accepted ? background_() : nullptr;
    const BackgroundEvidence evidence =
        background != nullptr
            ? background->Compare(bgr, if_apart.centre_px, if_apart.radius_px, roi)
            : BackgroundEvidence{};
    if (evidence.apart) {
      TakeEvidence(evidence, &if_apart);
      cand = std::move(if_apart);
    }
  }
  return cand;
}

void BallDetector::Decide(const BallRegion& region, const BallFit& fit, const std::string& fit_why,
                          double visible, double leak, BallCandidate* out) const {
  const BallDetectorOptions& o = options_;
  BallCandidate& cand = *out;
  // 3. Size: the radius limits and, with a posed camera, the ball's size at that place.
  const double radius = fit.ok && fit_why.empty() ? fit.radius_px : cand.radius_px;
  const Vector2d centre = fit.ok && fit_why.empty() ? fit.centre_px : cand.centre_px;
  double size_factor = 1.0;
  const std::string size_why = SizeProblem(centre, radius, &size_factor);
  // The region path checks the region's own size (a small ball's outline fit may hug its
  // saturated core and measure it too small while the region holds the whole ball).
  double region_size_factor = size_factor;
  const std::string region_size_why =
      region.ok && radius != region.radius_px
          ? SizeProblem(region.centre_px, region.radius_px, &region_size_factor)
          : size_why;
  // Where the region was measured, the outline fit alone does not decide: both must agree.
  const bool region_agrees = !o.use_region || !region.ok || !o.region_vetoes_fit ||
                             RegionProblem(region, o, min_arc_cover_, /*shape_only=*/true).empty();
  // A measured region must stand out from its surroundings on either path (min_contrast).
  const bool stands_out = !region.ok || StandsOut(region, o);
  const bool precise_ok =
      fit.ok && fit_why.empty() && size_why.empty() && region_agrees && stands_out;
  std::string region_why;
  if (!o.use_region) {
    region_why = "region check off";
  } else if (!region.ok) {
    region_why = region.failure;
  } else {
    region_why = RegionProblem(region, o, min_arc_cover_);
    if (region_why.empty()) region_why = region_size_why;
  }
  const bool region_accept = region_why.empty();
  cand.disc_shaped = region.ok && region_size_why.empty() &&
                     RegionProblem(region, o, min_arc_cover_, /*shape_only=*/true).empty();
  if (fit.ok) {
    cand.blurred = fit.blurred;
    cand.inlier_fraction = fit.inlier_fraction;
    cand.outside_fraction = fit.outside_fraction;
    cand.dents = fit.dents;
    cand.visible_fraction = visible;
  }
  const double region_score = region.ok ? region.arc_cover * std::min(1.0, region.fill / 0.9) *
                                              (1.0 - region.spill) * (1.0 - region.leak) *
                                              (region.radius_px / (region.radius_px + 1.0)) *
                                              region_size_factor
                                        : 0.0;
  // Balls stand out: the score grows with the contrast up to twice the least one (there).
  const double least_contrast = LeastContrastFactor(region, o) * o.min_contrast;
  const double contrast_factor = region.ok && least_contrast > 0
                                     ? std::clamp(region.contrast / (2 * least_contrast), 0.25, 1.0)
                                     : 1.0;
  if (precise_ok) {
    cand.centre_px = fit.centre_px;
    cand.radius_px = fit.radius_px;
    cand.sigma_px = fit.sigma_px;
    cand.precise = true;
    cand.score =
        std::max(region_score, fit.inlier_fraction * std::min(1.0, visible / 0.9) * (1.0 - leak) *
                                   std::exp(-0.5 * std::pow(fit.rms_px / 0.5, 2)) * size_factor);
    cand.score *= contrast_factor;
    cand.accepted = true;
  } else if (region_accept) {
    // The outline fit refines the region's centre when the two agree.
    if (fit.ok && (fit.centre_px - region.centre_px).norm() < 0.25 * region.radius_px &&
        std::abs(fit.radius_px - region.radius_px) < 0.25 * region.radius_px &&
        fit.inlier_fraction >= o.weak_min_inlier_fraction) {
      cand.centre_px = fit.centre_px;
      cand.radius_px = fit.radius_px;
      cand.sigma_px = std::max(fit.sigma_px, region.sigma_px * 0.5);
      cand.precise = true;
    }
    cand.score = region_score * contrast_factor;
    cand.accepted = true;
  } else {
    cand.accepted = false;
    cand.reason = !size_why.empty() ? size_why : (region.ok ? region_why : fit_why);
    // Both paths failed: the outline fit's own reason too (eval detect lists it with the miss).
    if (size_why.empty() && region.ok && !fit_why.empty() && fit_why != region_why) {
      cand.reason += "; outline fit: " + fit_why;
    }
    cand.score = region_score;
    cand.weak = fit.ok && size_why.empty() && !fit_why.empty() &&
                fit.inlier_fraction >= o.weak_min_inlier_fraction &&
                visible >= o.min_visible_fraction;
    if (cand.weak) {
      cand.centre_px = fit.centre_px;
      cand.radius_px = fit.radius_px;
      cand.sigma_px = fit.sigma_px;
    }
  }
}

std::optional<BallCandidate> BallDetector::FitAt(const cv::Mat& bgr, const cv::Rect& region,
                                                 const Vector2d& centre_px,
                                                 double radius_px) const {
  FV_REQUIRE(bgr.type() == CV_8UC3, "ball detector: the frame must be 8-bit BGR (got type {})",
             bgr.type());
  const BallDetectorOptions& o = options_;
  if (!centre_px.allFinite() || !std::isfinite(radius_px) || radius_px < 0.5 * o.min_radius_px ||
      radius_px > o.max_radius_px) {
    return std::nullopt;
  }
  // The fit's rays reach 1.6 radii and its edge search a few pixels beyond; they stop at the
  // image's border, so only the part of that square inside the image must lie in `region`.
  const cv::Rect image(0, 0, bgr.cols, bgr.rows);
  const cv::Rect roi = SearchArea(bgr.size(), region);
  const int reach = static_cast<int>(std::ceil(2.0 * radius_px + 6.0));
  const cv::Rect need =
      cv::Rect(static_cast<int>(std::floor(centre_px.x())) - reach,
               static_cast<int>(std::floor(centre_px.y())) - reach, 2 * reach + 2, 2 * reach + 2) &
      image;
  if (need.empty() || (need & roi) != need) return std::nullopt;
  // The widened class: the expected ball may be in shade, pale or blurred all over.
  const ColourTable& table = grow_table_ ? *grow_table_ : *table_;
  const uint8_t bit = grow_table_ ? grow_bit_ : ball_bit_;
  const std::optional<GuidedOutline> fit = FitGuidedOutline(bgr, table, bit, centre_px, radius_px);
  if (!fit) return std::nullopt;
  double visible = 0.0, leak = 1.0;
  DiscShares(bgr, table, bit, fit->centre_px, std::max(fit->radius_px - 0.7, 0.5),
             fit->radius_px + 1.5, fit->radius_px + 3.5, &visible, &leak);
  double size_factor = 1.0;
  if (visible < o.min_visible_fraction ||
      !SizeProblem(fit->centre_px, fit->radius_px, &size_factor).empty()) {
    return std::nullopt;
  }
  BallCandidate c;
  c.centre_px = fit->centre_px;
  c.radius_px = fit->radius_px;
  c.sigma_px = fit->sigma_px;
  c.accepted = true;
  c.guided = true;
  c.precise = true;
  c.visible_fraction = visible;
  c.inlier_fraction = fit->inlier_fraction;
  // Below a detected ball of the same fit: the place was given, not found.
  c.score = 0.5 * fit->inlier_fraction * std::min(1.0, visible / 0.9) *
            std::exp(-0.5 * std::pow(fit->rms_px / 0.5, 2)) * size_factor;
  return c;
}

std::optional<BallDetector::GuidedOutline> BallDetector::FitGuidedOutline(const cv::Mat& bgr,
                                                                          const ColourTable& table,
                                                                          uint8_t bit,
                                                                          const Vector2d& centre_px,
                                                                          double radius_px) const {
  const BallDetectorOptions& o = options_;
  const auto agrees = [&](const Vector2d& c, double r, double inliers, double rms) {
    return std::abs(r - radius_px) <= o.guided_radius_change * radius_px + 0.5 &&
           (c - centre_px).norm() <= o.guided_max_shift_radii * radius_px + 1.0 &&
           inliers >= o.weak_min_inlier_fraction && rms <= o.max_fit_rms_px;
  };
  const BallFit fit = FitBall(bgr, table, bit, centre_px, radius_px, camera_, o.fit);
  if (fit.ok && agrees(fit.centre_px, fit.radius_px, fit.inlier_fraction, fit.rms_px)) {
    return GuidedOutline{fit.centre_px, fit.radius_px, fit.sigma_px, fit.rms_px,
                         fit.inlier_fraction};
  }
  // The class does not outline it (a ball in front of a board of its colour): colour edges.
  EdgeCircleOptions eo;
  eo.min_step = o.fit.min_contrast;
  eo.max_radius_change = o.guided_radius_change;
  eo.max_shift_radii = o.guided_max_shift_radii;
  eo.inlier_px = o.fit.inlier_px;
  const EdgeCircle e = FitEdgeCircle(bgr, centre_px, radius_px, eo);
  if (e.ok && agrees(e.centre_px, e.radius_px, e.inlier_fraction, e.rms_px)) {
    return GuidedOutline{e.centre_px, e.radius_px, e.sigma_px, e.rms_px, e.inlier_fraction};
  }
  return std::nullopt;
}

void BallDetector::AddSmallBalls(const cv::Mat& bgr, const cv::Rect& roi,
                                 BallDetectionResult* result) const {
  const SmallBallOptions& o = options_.small;
  const bool widened = o.widened_class && grow_table_;
  const ColourTable& table = widened ? *grow_table_ : *table_;
  for (const SmallBall& s :
       FindSmallBalls(bgr, table, widened ? grow_bit_ : ball_bit_, roi, field_mask_, o)) {
    BallCandidate c;
    c.centre_px = s.centre_px;
    c.radius_px = s.radius_px;
    c.sigma_px = 0.5;
    c.small = true;
    c.contrast = s.contrast;
    // Below every candidate of the blob stages (0.5 at ten times the least contrast).
    c.score = 0.5 * std::min(1.0, s.contrast / (10 * o.min_contrast));
    double exp_min = 0, exp_max = 0;
    if (!ExpectedRadius(s.centre_px, &exp_min, &exp_max)) {
      // Without a posed camera the field around the spot decides (RejectSmallOffField).
      c.accepted = o.mode == "on" || !posed();
      if (!c.accepted) c.reason = "a small spot where no ball can be seen (small balls: auto)";
    } else if (SmallestPlausibleRadius(exp_min) > o.max_radius_px) {
      c.reason = fmt::format("a small spot where the ball looks larger ({:.1f} px)", exp_min);
    } else {
      c.accepted = true;
    }
    result->candidates.push_back(c);
  }
}

cv::Mat FieldMask(const camera::Camera& camera, const field::FieldModel& field, double margin_m,
                  double max_height_m) {
  const int cell = 4;
  const int gw = (camera.width + cell - 1) / cell, gh = (camera.height + cell - 1) / cell;
  cv::Mat coarse(gh, gw, CV_8U, cv::Scalar(0));
  const double hx = 0.5 * field.length_m + margin_m, hy = 0.5 * field.width_m + margin_m;
  for (int gy = 0; gy < gh; ++gy) {
    for (int gx = 0; gx < gw; ++gx) {
      const Vector2d uv(std::min(gx * cell + 0.5 * cell, camera.width - 1.0),
                        std::min(gy * cell + 0.5 * cell, camera.height - 1.0));
      const auto ray = camera.RayFromPixel(uv);
      if (!ray) {
        coarse.at<uint8_t>(gy, gx) = 255;  // unknown: do not hide anything
        continue;
      }
      double s_lo, s_hi;
      if (!HeightInterval(*ray, 0.0, max_height_m, 0.0, 1e4, &s_lo, &s_hi)) continue;
      const Vector3d a = ray->At(s_lo), b = ray->At(s_hi);
      if (SegmentMeetsRect(a.head<2>(), b.head<2>(), hx, hy)) coarse.at<uint8_t>(gy, gx) = 255;
    }
  }
  // Grow by one cell so the coarse grid never cuts a ball at the border.
  cv::dilate(coarse, coarse, cv::Mat(), cv::Point(-1, -1), 1);
  cv::Mat mask;
  cv::resize(coarse, mask, cv::Size(gw * cell, gh * cell), 0, 0, cv::INTER_NEAREST);
  return mask(cv::Rect(0, 0, camera.width, camera.height)).clone();
}

}  // namespace fv::detect
