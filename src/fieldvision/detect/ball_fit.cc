#include "fieldvision/detect/ball_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <mutex>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "fieldvision/camera/projection.h"
#include "fieldvision/detect/bilinear.h"
#include "fieldvision/util/error.h"

namespace fv::detect {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// sqrt(a) >= sqrt(b) for a, b >= 0, mostly without the square roots: below b (1 - 1e-12) the
// rounded roots differ (each is within an ulp of its root; the roots are over 1e-13 apart,
// relatively).
inline bool SqrtGe(double a, double b) {
  return a >= b || (a >= b * (1 - 1e-12) && std::sqrt(a) == std::sqrt(b));
}

// sqrt(a) >= h for a >= 0, mostly without the square root: decided on a against h^2 away from it.
class SqrtAtLeast {
 public:
  explicit SqrtAtLeast(double h)
      : h_(h), lo_(h * h * (1 - 1e-9)), hi_(h * h * (1 + 1e-9)), exact_(!(h * h > 1e-200)) {}
  bool operator()(double a) const {
    if (exact_ || (a >= lo_ && a <= hi_)) return std::sqrt(a) >= h_;
    return a > hi_;
  }

 private:
  double h_, lo_, hi_;
  bool exact_;
};

// std::lround (halves away from zero) without the library call for |x| < 1e9.
inline long RoundHalfAway(double x) {
  if (!(x > -1e9 && x < 1e9)) return std::lround(x);
  const long t = static_cast<long>(x);  // towards zero
  const double f = x - t;               // exact
  return f >= 0.5 ? t + 1 : f <= -0.5 ? t - 1 : t;
}

inline bool IsBall(const cv::Mat& img, const ColourTable& table, uint8_t bit, double x, double y) {
  const int xi = static_cast<int>(RoundHalfAway(x)), yi = static_cast<int>(RoundHalfAway(y));
  if (xi < 0 || yi < 0 || xi >= img.cols || yi >= img.rows) return false;
  const uint8_t* p = img.ptr<uint8_t>(yi) + 3 * static_cast<ptrdiff_t>(xi);
  return (table.Classify(p[0], p[1], p[2]) & bit) != 0;
}

// The ball's own colour where it is lit (BallFitOptions::shade_max_offset): the mean colour of
// its class pixels near the centre, whose multiples are the ball in shade.
struct BallShade {
  bool ok = false;
  Vector3d direction = Vector3d::Zero();  // unit
  double lit_sum = 0;                     // b + g + r
  // Whether the (bilinear) colour inside a step is the ball in shade: near the line of the
  // ball's colour scaled, darker than its lit part and than the step's outside. A mix of the lit
  // ball and the outside (blur, JPEG chroma) is not darker than both, whereas a mix with a dark
  // outside lies on that line too.
  bool Holds(const Vector3d& bgr, const Vector3d& outside, const BallFitOptions& o) const {
    if (!ok || o.shade_max_offset <= 0) return false;
    const double sum = bgr.sum();
    if (!(sum >= o.shade_min_brightness * lit_sum) || sum > lit_sum || sum >= outside.sum()) {
      return false;
    }
    return (bgr - bgr.dot(direction) * direction).norm() <= o.shade_max_offset;
  }
};

// The ball's class pixels within 0.8 r of c (at least five of them).
BallShade MeasureShade(const cv::Mat& img, const ColourTable& table, uint8_t bit, const Vector2d& c,
                       double r) {
  BallShade shade;
  const double reach = 0.8 * r;
  const int x0 = std::max(0, static_cast<int>(std::floor(c.x() - reach)));
  const int x1 = std::min(img.cols - 1, static_cast<int>(std::ceil(c.x() + reach)));
  const int y0 = std::max(0, static_cast<int>(std::floor(c.y() - reach)));
  const int y1 = std::min(img.rows - 1, static_cast<int>(std::ceil(c.y() + reach)));
  Vector3d total = Vector3d::Zero();
  int n = 0;
  for (int y = y0; y <= y1; ++y) {
    const uint8_t* row = img.ptr<uint8_t>(y);
    for (int x = x0; x <= x1; ++x) {
      if ((x - c.x()) * (x - c.x()) + (y - c.y()) * (y - c.y()) > reach * reach) continue;
      const uint8_t* p = row + 3 * static_cast<ptrdiff_t>(x);
      if ((table.Classify(p[0], p[1], p[2]) & bit) == 0) continue;
      total += Vector3d(p[0], p[1], p[2]);
      ++n;
    }
  }
  if (n < 5 || !(total.norm() > 0)) return shade;
  shade.ok = true;
  shade.direction = total.normalized();
  shade.lit_sum = total.sum() / n;
  return shade;
}

struct Edges {
  std::vector<Vector2d> points;
  std::vector<double> ramp_px;  // width of a motion-blur ramp at each point (0: sharp edge)
  int outside_ball = 0;         // rays whose outside is ball-coloured too
  int rays = 0;
  int clipped = 0;  // rays whose search leaves the image (SubpixelEdges)
};

// Rough outline: along each ray, where the colour class stops being the ball. A gap shorter than
// half the rough radius (a print's line, a seam, a dark patch of the shaded side) does not end it.
Edges ClassEdges(const cv::Mat& img, const ColourTable& table, uint8_t bit, const Vector2d& c,
                 double r0) {
  Edges e;
  e.rays = std::clamp(static_cast<int>(2 * M_PI * r0 / 1.5), 16, 96);
  const double t_max = 1.6 * r0 + 3.0;
  const int max_misses = std::max(2, static_cast<int>(std::lround(r0)));  // 0.5 px samples
  // Gaps within half the rough radius never end a ray: a rough centre on a print's line (a
  // dark cross through the ball) would otherwise give points next to it.
  const double min_edge = 0.5 * r0;
  for (int k = 0; k < e.rays; ++k) {
    const double th = 2 * M_PI * k / e.rays;
    const Vector2d u(std::cos(th), std::sin(th));
    bool seen = false;
    int misses = 0;
    double last_ball = 0;
    for (double t = 0; t <= t_max; t += 0.5) {
      const Vector2d p = c + t * u;
      if (p.x() < 0 || p.y() < 0 || p.x() > img.cols - 1 || p.y() > img.rows - 1) break;
      if (IsBall(img, table, bit, p.x(), p.y())) {
        seen = true;
        misses = 0;
        last_ball = t;
      } else if (seen && ++misses >= max_misses && last_ball >= min_edge) {
        break;
      }
    }
    // An outline point where the ball ends at least 1 px before the ray leaves the image or the
    // search (a ball clipped by the border gives none there).
    if (seen && misses >= 2 && last_ball >= min_edge) {
      e.points.push_back(c + (last_ball + 0.25) * u);
    }
  }
  return e;
}

// One candidate edge of a ray (c + t u, profile samples at(i) at t0 + i step, m of them) at the
// gradient peak `peak`: the ray's own colours 1.5 px inside and outside it (or the ray's ends
// across a wide motion-blur ramp) and where the profile crosses halfway between them. t < 0 when
// the step is too weak, its inside is not the ball, its outside is the ball too (outside_ball)
// or it is the edge of the ball's contact shadow on the field (shadow_band_ratio).
struct RayEdge {
  double t = -1, t10 = -1, t90 = -1;
  bool ramp = false;
  bool outside_ball = false;
};

template <typename Profile>
RayEdge EdgeAtPeak(const cv::Mat& img, const ColourTable& table, uint8_t bit, uint8_t field_bit,
                   const BallShade& shade, const Vector2d& c, const Vector2d& u, double t0,
                   double step, int m, int peak, Profile& at, const BallFitOptions& o) {
  constexpr double kSide = 1.5;
  RayEdge edge;
  int ia = std::max(0, peak - static_cast<int>(kSide / step));
  int ib = std::min(m - 1, peak + static_cast<int>(kSide / step));
  Vector3d a = 0.5 * (at(ia) + at(std::max(ia - 1, 0)));
  Vector3d b = 0.5 * (at(ib) + at(std::min(ib + 1, m - 1)));
  // A wide ramp (motion blur along this ray): the colours 3 px from the peak differ much more
  // than those 1.5 px from it, so both local colours lie on the ramp; use the ray's ends
  // instead (the halfway crossing of a swept disc is still its outline).
  const int ka = std::max(0, peak - static_cast<int>(2 * kSide / step));
  const int kb = std::min(m - 1, peak + static_cast<int>(2 * kSide / step));
  if ((at(kb) - at(ka)).squaredNorm() > 1.6 * 1.6 * (b - a).squaredNorm() &&
      IsBall(img, table, bit, c.x() + t0 * u.x(), c.y() + t0 * u.y())) {
    edge.ramp = true;
    ia = 0;
    ib = m - 1;
    a = at(0);
    b = at(m - 1);
  }
  const Vector3d ab = b - a;
  const double contrast2 = ab.squaredNorm();
  if (contrast2 < o.min_contrast * o.min_contrast) return edge;
  const Vector2d pin = c + (t0 + ia * step) * u, pout = c + (t0 + ib * step) * u;
  // The inside is neither the ball's class nor the ball in shade: the step lies beyond the ball.
  if (!IsBall(img, table, bit, pin.x(), pin.y()) && !shade.Holds(a, b, o)) return edge;
  if (IsBall(img, table, bit, pout.x(), pout.y())) {  // outside is ball-coloured
    edge.outside_ball = true;
    return edge;
  }
  if (field_bit != 0 && o.shadow_band_ratio > 0 && !edge.ramp &&
      IsBall(img, table, field_bit, pout.x(), pout.y())) {
    // The darkest sample between the inside and the step (BallFitOptions::shadow_band_ratio).
    int dark = ia;
    for (int i = ia + 1; i <= peak; ++i) {
      if (at(i).sum() < at(dark).sum()) dark = i;
    }
    if (at(dark).sum() < o.shadow_band_ratio * std::min(a.sum(), b.sum()) &&
        !shade.Holds(at(dark), b, o)) {
      return edge;
    }
  }
  double prev_p = (at(ia) - a).dot(ab) / contrast2;
  for (int i = ia + 1; i <= ib; ++i) {
    const double q = (at(i) - a).dot(ab) / contrast2;
    auto cross = [&](double level) {
      return t0 + (i - 1 + (level - prev_p) / (q - prev_p)) * step;
    };
    if (edge.t10 < 0 && prev_p < 0.1 && q >= 0.1) edge.t10 = cross(0.1);
    if (edge.t < 0 && prev_p < 0.5 && q >= 0.5) edge.t = cross(0.5);
    if (edge.t >= 0 && prev_p < 0.9 && q >= 0.9) {
      edge.t90 = cross(0.9);
      break;
    }
    prev_p = q;
  }
  return edge;
}

// SubpixelEdges's ray counts.
constexpr int kMinRays = 24, kMaxRays = 180;

// The directions (cos, sin) of SubpixelEdges's rays at 2 pi (k + 0.5) / rays, computed once for
// each ray count (kMinRays..kMaxRays).
const std::vector<std::pair<double, double>>& RayDirections(int rays) {
  static std::array<std::once_flag, kMaxRays + 1> once;
  static std::array<std::vector<std::pair<double, double>>, kMaxRays + 1> directions;
  std::call_once(once[rays], [rays] {
    auto& d = directions[rays];
    d.resize(rays);
    for (int k = 0; k < rays; ++k) {
      const double th = 2 * M_PI * (k + 0.5) / rays;
      d[k] = {std::cos(th), std::sin(th)};
    }
  });
  return directions[rays];
}

// Sub-pixel outline: along each ray from `c`, search around the reference radius ref(theta)
// for the outermost strong colour step from the ball to something else (EdgeAtPeak). Local
// references keep shading and a changing background (a line just beyond the ball) from biasing
// the edge.
Edges SubpixelEdges(const cv::Mat& img, const ColourTable& table, uint8_t bit,
                    const BallShade& shade, const Vector2d& c,
                    const std::function<double(double)>& ref, double mean_radius,
                    const BallFitOptions& o) {
  constexpr double kStep = 0.25, kSide = 1.5;
  Edges e;
  const uint8_t field_bit = table.ClassBitOrZero("field");
  // A degenerate reference (an ellipse or cone fit gone wild) gives no outline points.
  const double max_r = std::max(img.cols, img.rows);
  if (!std::isfinite(mean_radius) || mean_radius <= 0 || mean_radius > max_r) return e;
  e.rays = std::clamp(static_cast<int>(std::lround(2 * M_PI * mean_radius)), kMinRays, kMaxRays);
  const std::vector<std::pair<double, double>>& directions = RayDirections(e.rays);
  Sampler sample(img);
  std::vector<Vector3d> prof;
  std::vector<char> have;
  std::vector<double> grad2;
  std::vector<int> peaks;
  for (int k = 0; k < e.rays; ++k) {
    const double th = 2 * M_PI * (k + 0.5) / e.rays;
    const Vector2d u(directions[k].first, directions[k].second);
    const double r = ref(th);
    if (!std::isfinite(r) || r <= 0 || r > max_r) continue;
    const double half = std::max(2.0, 0.25 * r);
    const double t_lo = std::max(r - half, 0.5 * r), t_hi = r + half;
    const double t0 = std::min(0.35 * r, std::max(t_lo - kSide - kStep, 0.0));
    const double t_end = r + std::max(half, 0.6 * r) + 2.0;
    const int m = static_cast<int>((t_end - t0) / kStep) + 1;
    // The profile lies inside the image when both its ends do (Sampler::Inside); it is sampled
    // where it is read.
    const Vector2d p_first = c + t0 * u, p_last = c + (t0 + (m - 1) * kStep) * u;
    if (!InsideForSampling(img, p_first) || !InsideForSampling(img, p_last)) {
      ++e.clipped;
      continue;
    }
    prof.resize(m);
    have.assign(m, 0);
    const auto at = [&](int i) -> const Vector3d& {
      if (!have[i]) {
        const Vector2d p = c + (t0 + i * kStep) * u;
        sample.Inside(p.x(), p.y(), &prof[i]);
        have[i] = 1;
      }
      return prof[i];
    };
    // The search window [g_lo, g_hi] (t within [t_lo, t_hi]; m, -1: none), sampled at once. t
    // rises with i: the window's ends are found from the nearest indices.
    const auto t_at = [&](int i) { return t0 + i * kStep; };
    int g_lo = m, g_hi = -1;
    if (m >= 3) {
      int lo = std::clamp(static_cast<int>(std::ceil((t_lo - t0) / kStep)), 1, m - 1);
      while (lo > 1 && t_at(lo - 1) >= t_lo) --lo;
      while (lo < m - 1 && t_at(lo) < t_lo) ++lo;  // the first i >= 1 with t >= t_lo, or m - 1
      int hi = std::clamp(static_cast<int>(std::floor((t_hi - t0) / kStep)), 0, m - 2);
      while (hi < m - 2 && t_at(hi + 1) <= t_hi) ++hi;
      while (hi > 0 && t_at(hi) > t_hi) --hi;  // the last i <= m - 2 with t <= t_hi, or 0
      if (lo <= hi) {
        g_lo = lo;
        g_hi = hi;
      }
    }
    for (int i = g_lo - 1; i <= g_hi + 1; ++i) {
      const Vector2d p = c + (t0 + i * kStep) * u;
      sample.Inside(p.x(), p.y(), &prof[i]);
      have[i] = 1;
    }
    // Squared gradient magnitude (central differences over 0.5 px) in the search window: the
    // magnitude's comparisons are made on the squares (the square root is monotonic).
    grad2.assign(m, 0.0);
    double g2_max = 0;
    for (int i = g_lo; i <= g_hi; ++i) {
      grad2[i] = (prof[i + 1] - prof[i - 1]).squaredNorm();
      g2_max = std::max(g2_max, grad2[i]);
    }
    const double g_max = std::sqrt(g2_max);
    if (g_max < 0.1 * o.min_contrast) continue;
    // Peaks above half the largest, tried from the outermost inwards: the silhouette is the
    // outermost step from the ball to something else (a print's lines and the shading's
    // terminator lie inside it). Steps whose inside is not the ball (the background beyond it)
    // are passed over; one whose outside is the ball too ends the search. Outside the window
    // the gradient is 0, below half a positive largest.
    const SqrtAtLeast above_half(0.5 * g_max);
    const bool window_only = 0.5 * g_max > 0;
    const int p_lo = window_only ? std::max(2, g_lo) : 2;
    const int p_end = window_only ? std::min(m - 2, g_hi + 1) : m - 2;
    peaks.clear();
    for (int i = p_lo; i < p_end; ++i) {
      if (above_half(grad2[i]) && SqrtGe(grad2[i], grad2[i - 1]) &&
          SqrtGe(grad2[i], grad2[i + 1])) {
        peaks.push_back(i);
      }
    }
    double te = -1, t10 = -1, t90 = -1;
    bool ramp = false, outside_ball = false;
    for (auto it = peaks.rbegin(); it != peaks.rend() && te < 0; ++it) {
      const RayEdge edge =
          EdgeAtPeak(img, table, bit, field_bit, shade, c, u, t0, kStep, m, *it, at, o);
      if (edge.outside_ball) {  // the colour goes on beyond: no silhouette on this ray
        outside_ball = true;
        break;
      }
      te = edge.t;
      t10 = edge.t10;
      t90 = edge.t90;
      ramp = edge.ramp;
    }
    if (te < 0 && outside_ball) ++e.outside_ball;
    if (te < 0) continue;
    e.points.push_back(c + te * u);
    e.ramp_px.push_back(ramp && t10 >= 0 && t90 >= 0 ? (t90 - t10) / 0.8 : 0.0);
  }
  return e;
}

// Centre covariance of a circle through the inliers: sigma^2 (J^T J)^-1, J the Jacobian of the
// distances to the circle with respect to (cx, cy, r).
double CentreSigma(const std::vector<Vector2d>& pts, const std::vector<char>& inlier,
                   const Vector2d& c, double rms) {
  Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
  int n = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!inlier[i]) continue;
    const Vector2d d = pts[i] - c;
    const double len = std::max(d.norm(), 1e-9);
    const Vector3d j(-d.x() / len, -d.y() / len, -1.0);
    jtj += j * j.transpose();
    ++n;
  }
  const double s = std::max(rms * std::sqrt(double(n) / std::max(n - 3, 1)), 0.15);
  Eigen::FullPivLU<Eigen::Matrix3d> lu(jtj);
  if (n < 3 || !lu.isInvertible()) return 10.0;
  const Eigen::Matrix3d cov = s * s * lu.inverse();
  return std::sqrt(std::max(0.5 * (cov(0, 0) + cov(1, 1)), 0.0)) + 0.02;
}

// The cone of rays tangent to the sphere: unit rays v_i with v_i . w = 1.
bool FitCone(const std::vector<Vector3d>& rays, const std::vector<char>& use, Vector3d* axis,
             double* half_angle) {
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Vector3d atb = Vector3d::Zero();
  int n = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (!use[i]) continue;
    ata += rays[i] * rays[i].transpose();
    atb += rays[i];
    ++n;
  }
  if (n < 3) return false;
  const Vector3d w = ata.ldlt().solve(atb);
  const double len = w.norm();
  if (!std::isfinite(len) || len < 1.0) return false;  // cos(alpha) = 1 / |w| must be <= 1
  *axis = w / len;
  *half_angle = std::acos(1.0 / len);
  return true;
}

double Rms(const std::vector<double>& res, const std::vector<char>& inlier, int* count) {
  double s = 0;
  int n = 0;
  for (size_t i = 0; i < res.size(); ++i) {
    if (inlier[i]) {
      s += res[i] * res[i];
      ++n;
    }
  }
  *count = n;
  return n > 0 ? std::sqrt(s / n) : 0.0;
}

// Distance of p from an ellipse (approximate: along the ray from its centre).
double EllipseDistance(const cv::RotatedRect& e, const Vector2d& p) {
  const double th = e.angle * M_PI / 180.0;
  const Vector2d d = p - Vector2d(e.center.x, e.center.y);
  const double x = std::cos(th) * d.x() + std::sin(th) * d.y();
  const double y = -std::sin(th) * d.x() + std::cos(th) * d.y();
  const double a = 0.5 * e.size.width, b = 0.5 * e.size.height;
  const double rho = std::sqrt((x / a) * (x / a) + (y / b) * (y / b));
  if (rho < 1e-9) return std::min(a, b);
  return d.norm() * (1.0 - 1.0 / rho);
}

double EllipsePolarRadius(const cv::RotatedRect& e, double direction) {
  const double th = direction - e.angle * M_PI / 180.0;
  const double a = 0.5 * e.size.width, b = 0.5 * e.size.height;
  const double c = std::cos(th), s = std::sin(th);
  return 1.0 / std::sqrt((c / a) * (c / a) + (s / b) * (s / b));
}

// Sorts (angle, radius) samples as std::sort does. Samples taken once round a convex outline are
// already in order but for a rotation, or its reverse: then in linear time.
void SortPolar(std::vector<std::pair<double, double>>* polar) {
  auto& v = *polar;
  const size_t n = v.size();
  // Where the angles, cyclically, rise strictly but for one step down (n when they do not).
  const auto rotation_start = [&v, n] {
    size_t downs = 0, start = n;
    for (size_t i = 0; i < n; ++i) {
      const double a = v[i].first, b = v[i + 1 < n ? i + 1 : 0].first;
      if (!(a < b || b < a)) return n;  // equal or NaN
      if (b < a) {
        ++downs;
        start = (i + 1) % n;
      }
    }
    return downs == 1 ? start : n;
  };
  size_t start = rotation_start();
  if (start == n) {
    std::reverse(v.begin(), v.end());
    start = rotation_start();
  }
  if (start == n) {
    std::sort(v.begin(), v.end());
  } else {
    std::rotate(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(start), v.end());
  }
}

// The image outline of the cone (axis, half-angle) as a polar function around the projection
// of the axis: the search reference for outline points of a sphere seen in perspective.
struct ConeOutline {
  static constexpr int kSamples = 720;
  bool ok = false;
  Vector2d centre = Vector2d::Zero();
  double mean_radius = 0.0;
  std::vector<double> radius_at;  // per degree

  ConeOutline(const camera::Camera& cam, const Vector3d& axis, double alpha) {
    const auto c = cam.ProjectFromCamera(axis);
    if (!c) return;
    centre = *c;
    const Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
    // cos and sin of the 720 directions around the axis, computed once.
    static const std::array<std::pair<double, double>, kSamples> kCosSin = [] {
      std::array<std::pair<double, double>, kSamples> cs;
      for (int k = 0; k < kSamples; ++k) {
        const double phi = 2 * M_PI * k / kSamples;
        cs[k] = {std::cos(phi), std::sin(phi)};
      }
      return cs;
    }();
    const Vector3d along = std::cos(alpha) * axis;
    const double sin_alpha = std::sin(alpha);
    // Directions about 2 px of outline apart or closer, at most 2 degrees (the table below holds
    // a radius a degree; between samples the outline is off its chord by r (1 - cos 1 deg), under
    // 0.01 px below 60 px): every 4th of the 720 below 60 px of radius, every 2nd below 120 px.
    const double approx_radius_px = std::max(cam.fx, cam.fy) * std::tan(alpha);
    const int stride = approx_radius_px < 60 ? 4 : approx_radius_px < 120 ? 2 : 1;
    std::vector<std::pair<double, double>> polar;
    polar.reserve(kSamples / stride);
    // Camera::ProjectFromCamera with the intrinsics gathered once.
    const auto intrinsics = cam.IntrinsicsBlock();
    for (int k = 0; k < kSamples; k += stride) {
      const Vector3d v = along + sin_alpha * (kCosSin[k].first * e1 + kCosSin[k].second * e2);
      Vector2d p;
      if (!camera::ProjectCameraPoint(intrinsics.data(), v.data(), p.data())) return;
      const Vector2d d = p - centre;
      double th = std::atan2(d.y(), d.x());
      if (th < 0) th += 2 * M_PI;
      polar.push_back({th, d.norm()});
    }
    SortPolar(&polar);
    radius_at.assign(360, 0.0);
    size_t j = 0;
    for (int deg = 0; deg < 360; ++deg) {
      const double th = deg * M_PI / 180.0;
      while (j < polar.size() && polar[j].first < th) ++j;
      const auto& hi = polar[j % polar.size()];
      const auto& lo = polar[(j + polar.size() - 1) % polar.size()];
      double span = hi.first - lo.first;
      double off = th - lo.first;
      if (span <= 0) span += 2 * M_PI;
      if (off < 0) off += 2 * M_PI;
      radius_at[deg] = lo.second + (hi.second - lo.second) * std::clamp(off / span, 0.0, 1.0);
      mean_radius += radius_at[deg] / 360.0;
    }
    ok = mean_radius > 0.5;
  }
  double operator()(double th) const {
    double deg = th * 180.0 / M_PI;
    deg -= 360.0 * std::floor(deg / 360.0);
    const int a = static_cast<int>(deg) % 360, b = (a + 1) % 360;
    const double f = deg - std::floor(deg);
    return (1 - f) * radius_at[a] + f * radius_at[b];
  }
};

// Robust cone fit of outline pixels: initial inliers are `inl` (or those within the band of a
// given cone: thr outside it, thr_in inside it), then three rounds of fit and re-selection.
// `res` receives pixel residuals.
bool RobustCone(const std::vector<Vector2d>& pts, const camera::Camera& cam, double thr,
                double thr_in, const Vector3d* axis0, double alpha0, std::vector<char>* inl,
                std::vector<double>* res, Vector3d* axis, double* alpha) {
  const int n = static_cast<int>(pts.size());
  std::vector<Vector3d> rays(n);
  std::vector<char> ok(n, 1);
  for (int i = 0; i < n; ++i) {
    const auto xn = cam.Undistort(pts[i]);
    if (!xn) {
      ok[i] = 0;
      rays[i] = Vector3d::UnitZ();
      continue;
    }
    rays[i] = Vector3d(xn->x(), xn->y(), 1.0).normalized();
  }
  const double f = std::sqrt(cam.fx * cam.fy);
  res->assign(n, 0.0);
  inl->resize(n);
  const auto residual = [&](int i, const Vector3d& ax, double al) {
    return (std::acos(std::clamp(rays[i].dot(ax), -1.0, 1.0)) - al) * f;
  };
  const auto select = [&](const Vector3d& ax, double al) {
    for (int i = 0; i < n; ++i) {
      (*res)[i] = residual(i, ax, al);
      (*inl)[i] = ok[i] && (*res)[i] < thr && (*res)[i] > -thr_in;
    }
  };
  // The inlier flags alone (the residuals are those of the next selection): a ray is an inlier
  // when its angle to the axis lies in the band al -+ thr / f, decided on its cosine against the
  // cosines of the band's ends, 1e-12 away from them (at least 1e-12 rad, far beyond the
  // rounding of acos and of the residual), else by the residual. False when the band comes
  // within 1e-6 of 0 or pi: then select.
  const auto select_flags = [&](const Vector3d& ax, double al) {
    const double lo = al - thr_in / f, hi = al + thr / f;
    if (!(lo > 1e-6 && hi < M_PI - 1e-6)) return false;
    const double c_lo = std::cos(hi), c_hi = std::cos(lo), eps = 1e-12;
    for (int i = 0; i < n; ++i) {
      const double c = std::clamp(rays[i].dot(ax), -1.0, 1.0);
      if (c < c_lo - eps || c > c_hi + eps) {
        (*inl)[i] = 0;
      } else if (c > c_lo + eps && c < c_hi - eps) {
        (*inl)[i] = ok[i];
      } else {
        const double r = residual(i, ax, al);
        (*inl)[i] = ok[i] && r < thr && r > -thr_in;
      }
    }
    return true;
  };
  // The cone of the last selection whose residuals are not in `res` yet.
  bool res_pending = false;
  Vector3d pending_axis = Vector3d::Zero();
  double pending_alpha = 0;
  const auto select_pending = [&](const Vector3d& ax, double al) {
    res_pending = select_flags(ax, al);
    if (res_pending) {
      pending_axis = ax;
      pending_alpha = al;
    } else {
      select(ax, al);
    }
  };
  if (axis0 != nullptr) {
    select_pending(*axis0, alpha0);
  } else {
    for (int i = 0; i < n; ++i) (*inl)[i] = (*inl)[i] && ok[i];
  }
  for (int round = 0; round < 3; ++round) {
    if (!FitCone(rays, *inl, axis, alpha)) {
      if (res_pending) {
        for (int i = 0; i < n; ++i) (*res)[i] = residual(i, pending_axis, pending_alpha);
      }
      return false;
    }
    if (round < 2) {
      select_pending(*axis, *alpha);
    } else {
      select(*axis, *alpha);
    }
  }
  return std::count(inl->begin(), inl->end(), 1) >= 3;
}

}  // namespace

void BallFitOptions::Check() const {
  CheckNonNegative(min_contrast, "BallFitOptions.min_contrast");
  CheckPositive(inlier_px, "BallFitOptions.inlier_px");
  FV_REQUIRE(ransac_iterations >= 1, "BallFitOptions.ransac_iterations must be >= 1");
  FV_REQUIRE(blur_min_aspect >= 1.0, "BallFitOptions.blur_min_aspect must be >= 1");
  FV_REQUIRE(inside_share > 0.0 && inside_share <= 1.0,
             "BallFitOptions.inside_share must be in (0, 1] (got {})", inside_share);
  CheckInRange(shade_max_offset, 0.0, 255.0, "BallFitOptions.shade_max_offset");
  CheckInRange(shade_min_brightness, 0.0, 1.0, "BallFitOptions.shade_min_brightness");
  CheckInRange(shadow_band_ratio, 0.0, 1.0, "BallFitOptions.shadow_band_ratio");
}

std::string BallFit::Summary() const {
  if (!ok) return "no fit: " + failure;
  return fmt::format(
      "centre ({:.2f}, {:.2f}) px, radius {:.2f} px, sigma {:.3f} px, {}/{} rays "
      "on the outline, rms {:.3f} px, {:.0f} % outside{}",
      centre_px.x(), centre_px.y(), radius_px, sigma_px, inliers, rays, rms_px,
      100 * outside_fraction, blurred ? fmt::format(", blurred {:.1f} px", blur_length_px) : "");
}

bool CircleFrom3(const Vector2d& a, const Vector2d& b, const Vector2d& c, Vector2d* centre,
                 double* radius) {
  const double d =
      2 * (a.x() * (b.y() - c.y()) + b.x() * (c.y() - a.y()) + c.x() * (a.y() - b.y()));
  if (std::abs(d) < 1e-9) return false;
  const double a2 = a.squaredNorm(), b2 = b.squaredNorm(), c2 = c.squaredNorm();
  centre->x() = (a2 * (b.y() - c.y()) + b2 * (c.y() - a.y()) + c2 * (a.y() - b.y())) / d;
  centre->y() = (a2 * (c.x() - b.x()) + b2 * (a.x() - c.x()) + c2 * (b.x() - a.x())) / d;
  *radius = (a - *centre).norm();
  return std::isfinite(*radius);
}

bool FitCircle(const std::vector<Vector2d>& pts, double inlier_px, Vector2d* centre, double* radius,
               std::vector<char>* inlier, double inside_px) {
  if (inside_px < 0) inside_px = inlier_px;
  const int n = static_cast<int>(pts.size());
  inlier->assign(n, 1);
  if (n < 3) return false;
  if (!(*radius > 0)) {
    // Kasa's algebraic fit as the start.
    Eigen::MatrixXd a(n, 3);
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) {
      a.row(i) << pts[i].x(), pts[i].y(), 1.0;
      b(i) = -pts[i].squaredNorm();
    }
    const Vector3d s = a.colPivHouseholderQr().solve(b);
    *centre = Vector2d(-0.5 * s(0), -0.5 * s(1));
    *radius = std::sqrt(std::max(centre->squaredNorm() - s(2), 1e-9));
  }
  Vector2d c = *centre;
  double r = *radius;
  for (int round = 0; round < 4; ++round) {
    int count = 0;
    for (int i = 0; i < n; ++i) {
      const double e = (pts[i] - c).norm() - r;
      (*inlier)[i] = e < inlier_px && e > -inside_px;
      count += (*inlier)[i];
    }
    if (count < 3) return false;
    for (int it = 0; it < 6; ++it) {
      // J^T J and J^T r of the rows j = (jx, jy, -1), as j j^T and j (len - r) sum them: the
      // products with -1 are exact negations, each symmetric entry is summed once.
      double xx = 0, xy = 0, yy = 0, x1 = 0, y1 = 0, n1 = 0, gx = 0, gy = 0, g1 = 0;
      for (int i = 0; i < n; ++i) {
        if (!(*inlier)[i]) continue;
        const Vector2d d = pts[i] - c;
        const double len = std::max(d.norm(), 1e-9);
        const double jx = -d.x() / len, jy = -d.y() / len, res = len - r;
        xx += jx * jx;
        xy += jx * jy;
        yy += jy * jy;
        x1 -= jx;
        y1 -= jy;
        n1 += 1.0;
        gx += jx * res;
        gy += jy * res;
        g1 -= res;
      }
      Eigen::Matrix3d jtj;
      jtj << xx, xy, x1, xy, yy, y1, x1, y1, n1;
      const Vector3d jtr(gx, gy, g1);
      const Vector3d step = -jtj.ldlt().solve(jtr);
      if (!step.allFinite()) return false;
      c += step.head<2>();
      r += step(2);
      if (step.norm() < 1e-6) break;
    }
  }
  *centre = c;
  *radius = r;
  return std::isfinite(r) && r > 0;
}

bool RansacCircle(const std::vector<Vector2d>& pts, double thr, int iterations, Vector2d* centre,
                  double* radius, std::vector<char>* inlier) {
  const int n = static_cast<int>(pts.size());
  if (n < 3) return false;
  uint64_t state = 0x9E3779B97F4A7C15ull ^ uint64_t(n);
  auto next = [&](int m) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<int>((state >> 33) % uint64_t(m));
  };
  int best = -1;
  Vector2d best_c = Vector2d::Zero();
  double best_r = 0;
  for (int it = 0; it < iterations; ++it) {
    const int i = next(n), j = next(n), k = next(n);
    if (i == j || j == k || i == k) continue;
    Vector2d c;
    double r;
    if (!CircleFrom3(pts[i], pts[j], pts[k], &c, &r)) continue;
    // A triple that cannot beat the best even with every remaining point an inlier stops.
    int count = 0, left = n;
    for (const auto& p : pts) {
      if (count + left <= best) break;
      count += std::abs((p - c).norm() - r) < thr;
      --left;
    }
    if (left == 0 && count > best) {
      best = count;
      best_c = c;
      best_r = r;
    }
  }
  if (best < 3) return false;
  *centre = best_c;
  *radius = best_r;
  return FitCircle(pts, thr, centre, radius, inlier);
}

namespace {

// The outline fit in progress: the edge points, which are inliers, their residuals (filled by the
// cone fit, else at the end) and the current circle.
struct OutlineState {
  BallShade shade;
  Edges edges;
  std::vector<char> inl;
  std::vector<double> res;
  Vector2d centre = Vector2d::Zero();
  double radius = 0;
  bool cone = false;  // centre and radius come from a cone (FitSphereCone), not a circle
};

// 1. and 2.: the rough outline from the colour classes with a robust circle, then the sub-pixel
// outline twice (the second from the refined circle). "" or why it failed.
std::string SubpixelCircle(const cv::Mat& bgr, const ColourTable& table, uint8_t ball_bit,
                           const Vector2d& rough_centre_px, double r0, const BallFitOptions& o,
                           OutlineState* s) {
  const Edges rough = ClassEdges(bgr, table, ball_bit, rough_centre_px, r0);
  if (rough.points.size() < 5) return "too few outline points";
  Vector2d c1;
  double r1 = 0;
  std::vector<char> in1;
  if (!RansacCircle(rough.points, std::max(1.0, 0.08 * r0), o.ransac_iterations, &c1, &r1, &in1) ||
      r1 > 3 * r0 + 3) {
    return "no circle in the rough outline";
  }
  s->shade = MeasureShade(bgr, table, ball_bit, c1, r1);
  for (int pass = 0; pass < 2; ++pass) {
    s->edges = SubpixelEdges(
        bgr, table, ball_bit, s->shade, c1, [r1](double) { return r1; }, r1, o);
    Vector2d c2 = c1;
    double r2 = r1;
    const double band = o.inlier_px + 0.03 * r1 + (pass == 0 ? 0.5 : 0.0);
    if (!FitCircle(s->edges.points, band, &c2, &r2, &s->inl, o.inside_share * band)) {
      return "too few sub-pixel outline points";
    }
    c1 = c2;
    r1 = r2;
  }
  s->centre = c1;
  s->radius = r1;
  return "";
}

// 3. With a camera: the cone of the sphere (its predicted outline guides two more passes of
// outline points, so a sphere seen far off the axis, an ellipse, is searched where it is); the
// circle when no cone fits.
void FitSphereCone(const cv::Mat& bgr, const ColourTable& table, uint8_t ball_bit,
                   const camera::Camera& camera, double thr, const BallFitOptions& o,
                   OutlineState* s) {
  Vector3d axis;
  double alpha = 0;
  bool have_cone = false;
  for (int pass = 0; pass < 3; ++pass) {
    if (have_cone) {
      const ConeOutline outline(camera, axis, alpha);
      if (!outline.ok) break;
      Edges next = SubpixelEdges(
          bgr, table, ball_bit, s->shade, outline.centre,
          [&outline](double th) { return outline(th); }, outline.mean_radius, o);
      if (next.points.size() < 5) break;
      s->edges = std::move(next);
      s->inl.assign(s->edges.points.size(), 1);
    }
    Vector3d new_axis;
    double new_alpha = 0.0;
    if (!RobustCone(s->edges.points, camera, thr, o.inside_share * thr, have_cone ? &axis : nullptr,
                    have_cone ? alpha : 0.0, &s->inl, &s->res, &new_axis, &new_alpha)) {
      break;
    }
    axis = new_axis;
    alpha = new_alpha;
    have_cone = true;
  }
  const auto uv = have_cone ? camera.ProjectFromCamera(axis) : std::nullopt;
  if (!uv) {
    FitCircle(s->edges.points, thr, &s->centre, &s->radius, &s->inl);
    return;
  }
  s->centre = *uv;
  s->cone = true;
  double sum = 0;
  int cnt = 0;
  for (size_t i = 0; i < s->edges.points.size(); ++i) {
    if (s->inl[i]) {
      sum += (s->edges.points[i] - s->centre).norm();
      ++cnt;
    }
  }
  if (cnt > 0) s->radius = sum / cnt;
}

// The outline's inliers and residuals for the checks (outside share, dents, inliers) from a
// circle fitted with the same band both ways, from the outer outline's: a polygon's corners
// stick out of that one, where the outer outline's circle passes near them.
void ClassifyBothWays(const camera::Camera* camera, double thr, OutlineState* s) {
  Vector2d c = s->centre;
  double r = s->radius;
  std::vector<char> inl;
  if (!FitCircle(s->edges.points, thr, &c, &r, &inl)) return;
  if (s->cone && camera != nullptr) {
    // The cone from the circle's inliers, as the first cone pass does.
    std::vector<double> res;
    Vector3d axis;
    double alpha = 0;
    if (RobustCone(s->edges.points, *camera, thr, thr, nullptr, 0.0, &inl, &res, &axis, &alpha)) {
      s->inl = std::move(inl);
      s->res = std::move(res);
    }
    return;
  }
  s->inl = std::move(inl);
  for (size_t i = 0; i < s->edges.points.size(); ++i) {
    s->res[i] = (s->edges.points[i] - c).norm() - r;
  }
}

// 4. Motion blur: an elongated outline that an ellipse explains much better than the circle
// (`count` inliers, `rms`) replaces it; sets fit->blurred.
void TryMotionBlurEllipse(const cv::Mat& bgr, const ColourTable& table, uint8_t ball_bit,
                          double thr, const BallFitOptions& o, OutlineState* s, int* count,
                          double* rms, BallFit* fit) {
  const int n = static_cast<int>(s->edges.points.size());
  std::vector<cv::Point2f> cv_pts;
  for (const auto& p : s->edges.points) cv_pts.emplace_back(float(p.x()), float(p.y()));
  cv::RotatedRect e = cv::fitEllipseDirect(cv_pts);
  for (int pass = 0; pass < 2 && e.size.width > 0 && e.size.height > 0; ++pass) {
    const Vector2d ec(e.center.x, e.center.y);
    const double mean_r = 0.25 * (e.size.width + e.size.height);
    const Edges be = SubpixelEdges(
        bgr, table, ball_bit, s->shade, ec, [&e](double th) { return EllipsePolarRadius(e, th); },
        mean_r, o);
    if (be.points.size() < 8) break;
    cv_pts.clear();
    for (const auto& p : be.points) cv_pts.emplace_back(float(p.x()), float(p.y()));
    const cv::RotatedRect e2 = cv::fitEllipseDirect(cv_pts);
    if (!(e2.size.width > 0 && e2.size.height > 0)) break;
    int ecount = 0;
    double es = 0;
    for (const auto& p : be.points) {
      const double d = EllipseDistance(e2, p);
      if (std::abs(d) < thr) {
        ++ecount;
        es += d * d;
      }
    }
    const double major = std::max(e2.size.width, e2.size.height);
    const double minor = std::min(e2.size.width, e2.size.height);
    e = e2;
    if (pass == 1 && ecount >= 0.9 * be.points.size() && major / minor >= o.blur_min_aspect &&
        double(ecount) / be.rays > double(*count) / n) {
      fit->blurred = true;
      fit->blur_length_px = major - minor;
      s->centre = Vector2d(e2.center.x, e2.center.y);
      s->radius = 0.5 * minor;
      *rms = std::sqrt(es / ecount);
      s->edges = be;
      *count = ecount;
      fit->rays = be.rays;
      fit->edges = static_cast<int>(be.points.size());
      s->inl.assign(be.points.size(), 0);
      for (size_t i = 0; i < be.points.size(); ++i) {
        s->inl[i] = std::abs(EllipseDistance(e2, be.points[i])) < thr;
      }
    }
  }
}

// A blur seen as wide edge ramps on at least 15 % of the outline (length: their 75th percentile).
void BlurFromRamps(const Edges& edges, BallFit* fit) {
  std::vector<double> ramps;
  for (double w : edges.ramp_px) {
    if (w > 3.0) ramps.push_back(w);
  }
  if (!edges.ramp_px.empty() && ramps.size() >= 0.15 * edges.ramp_px.size()) {
    std::sort(ramps.begin(), ramps.end());
    fit->blurred = true;
    fit->blur_length_px = ramps[ramps.size() * 3 / 4];
  }
}

// Arcs (two or more consecutive points) of the outline that lie inside the fit: one or two for
// an occluder.
int CountDents(const std::vector<double>& res, const std::vector<char>& inl) {
  const int m = static_cast<int>(std::min(res.size(), inl.size()));
  const auto dent = [&](int i) { return !inl[i] && res[i] < 0; };
  int first_break = -1;
  for (int i = 0; i < m; ++i) {
    if (!dent(i)) {
      first_break = i;
      break;
    }
  }
  if (first_break < 0) return 0;
  int dents = 0, run = 0;
  for (int j = 1; j <= m; ++j) {
    const int i = (first_break + j) % m;
    if (dent(i)) {
      ++run;
    } else {
      dents += run >= 2;
      run = 0;
    }
  }
  return dents;
}

}  // namespace

BallFit FitBall(const cv::Mat& bgr, const ColourTable& table, uint8_t ball_bit,
                const Vector2d& rough_centre_px, double rough_radius_px,
                const camera::Camera* camera, const BallFitOptions& o) {
  o.Check();
  BallFit fit;
  OutlineState s;
  fit.failure =
      SubpixelCircle(bgr, table, ball_bit, rough_centre_px, std::max(rough_radius_px, 1.0), o, &s);
  if (!fit.failure.empty()) return fit;
  const double thr = o.inlier_px + 0.03 * s.radius;
  if (camera != nullptr) FitSphereCone(bgr, table, ball_bit, *camera, thr, o, &s);
  const int n = static_cast<int>(s.edges.points.size());
  fit.rays = s.edges.rays;
  fit.edges = n;
  if (s.res.size() != s.edges.points.size()) {
    s.res.resize(n);
    for (int i = 0; i < n; ++i) s.res[i] = (s.edges.points[i] - s.centre).norm() - s.radius;
  }
  if (o.inside_share < 1.0) ClassifyBothWays(camera, thr, &s);
  int count = 0;
  double rms = Rms(s.res, s.inl, &count);
  if (count < 0.8 * n && n >= 8) {
    TryMotionBlurEllipse(bgr, table, ball_bit, thr, o, &s, &count, &rms, &fit);
  }
  if (!fit.blurred) BlurFromRamps(s.edges, &fit);
  int outside = s.edges.outside_ball;
  for (size_t i = 0; i < s.res.size() && i < s.inl.size(); ++i) {
    outside += !s.inl[i] && s.res[i] > 0;
  }
  fit.outside_fraction = fit.rays > 0 ? double(outside) / fit.rays : 0.0;
  fit.dents = CountDents(s.res, s.inl);
  // A fit that ran off (a degenerate cone or ellipse) is no fit of this seed.
  const double reach = 10.0 * std::max(rough_radius_px, 1.0) + 10.0;
  if (!s.centre.allFinite() || !std::isfinite(s.radius) ||
      (s.centre - rough_centre_px).norm() > reach || s.radius > reach) {
    fit.failure = "outline fit ran off its seed";
    return fit;
  }
  fit.ok = true;
  fit.centre_px = s.centre;
  fit.radius_px = s.radius;
  fit.rms_px = rms;
  fit.inliers = count;
  // A ball cut by the image's border is judged on the rays that stay inside the image (at least
  // half of them: less outline is too little to call round).
  const int judged = std::max(fit.rays - s.edges.clipped, (fit.rays + 1) / 2);
  fit.inlier_fraction = judged > 0 ? double(count) / judged : 0.0;
  fit.sigma_px = CentreSigma(s.edges.points, s.inl, s.centre, rms);
  if (fit.blurred) fit.sigma_px = std::hypot(fit.sigma_px, 0.05 * fit.blur_length_px);
  fit.edge_points = std::move(s.edges.points);
  fit.edge_inlier = std::move(s.inl);
  return fit;
}

}  // namespace fv::detect
