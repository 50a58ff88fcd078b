// Two rays: the closest point of two lines in closed form (the seeds' midpoint method).
#include "fieldvision/recon/triangulation.h"

#include <algorithm>
#include <cmath>

#include "fieldvision/recon/triangulation_internal.h"
#include "fieldvision/util/error.h"

namespace fv::recon {

using detail::kRadToDeg;

RayPairResult ClosestPointOfRays(const geometry::Ray3d& a, const geometry::Ray3d& b,
                                 double min_angle_deg) {
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

}  // namespace fv::recon
