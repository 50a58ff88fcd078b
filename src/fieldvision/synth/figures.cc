#include "fieldvision/synth/figures.h"

#include <algorithm>
#include <cmath>

namespace fv::synth {
namespace {

// Stride length (one full gait cycle, two steps) at a speed: ~1.6 m walking, ~3 m running.
double StrideM(double speed_mps) { return 1.0 + 0.4 * speed_mps; }

double SphereHit(const Eigen::Vector3d& ro, const Eigen::Vector3d& rd, const Eigen::Vector3d& c,
                 double r) {
  const Eigen::Vector3d oc = ro - c;
  const double b = oc.dot(rd);
  const double cc = oc.squaredNorm() - r * r;
  const double h = b * b - cc;
  if (h < 0) return -1;
  return -b - std::sqrt(h);
}

}  // namespace

PathState PathAt(const PathSpec& path, double time_s) {
  PathState s;
  const auto& w = path.waypoints_m;
  s.position_m = w.front();
  const int legs = static_cast<int>(w.size()) - 1;
  if (legs >= 1 && (w[1] - w[0]).norm() > 1e-9) s.heading = (w[1] - w[0]).normalized();
  if (legs < 1 || time_s <= path.start_s) return s;
  std::vector<double> T(legs), rate(legs);
  double total_t = 0, total_p = 0;
  for (int i = 0; i < legs; ++i) {
    const double speed = path.speeds_mps.empty() ? path.speed_mps : path.speeds_mps[i];
    T[i] = (w[i + 1] - w[i]).norm() / speed;
    rate[i] = speed / StrideM(speed);
    total_t += T[i];
    total_p += T[i] * rate[i];
  }
  if (total_t <= 1e-12) return s;
  const double te = time_s - path.start_s;
  const double n = std::floor(te / (2 * total_t));
  const double tm = te - n * 2 * total_t;
  const bool forward = tm < total_t;
  const double tau = forward ? tm : 2 * total_t - tm;
  double t_cum = 0, p_cum = 0;
  int i = 0;
  while (i < legs - 1 && t_cum + T[i] < tau) {
    t_cum += T[i];
    p_cum += T[i] * rate[i];
    ++i;
  }
  const double frac = T[i] > 0 ? std::clamp((tau - t_cum) / T[i], 0.0, 1.0) : 1.0;
  s.position_m = w[i] + frac * (w[i + 1] - w[i]);
  const Eigen::Vector2d d = w[i + 1] - w[i];
  if (d.norm() > 1e-9) s.heading = (forward ? 1.0 : -1.0) * d.normalized();
  s.speed_mps = path.speeds_mps.empty() ? path.speed_mps : path.speeds_mps[i];
  const double p_forward = p_cum + (tau - t_cum) * rate[i];
  s.gait_cycles = n * 2 * total_p + (forward ? p_forward : 2 * total_p - p_forward);
  return s;
}

Body PersonBody(const PersonSpec& person, const TeamSpec& team, double time_s) {
  const PathState ps = PathAt(person.path, time_s);
  const double H = person.height_m, k = H / 1.8;
  const Eigen::Vector3d f(ps.heading.x(), ps.heading.y(), 0);
  const Eigen::Vector3d l(-ps.heading.y(), ps.heading.x(), 0);
  const Eigen::Vector3d z(0, 0, 1);
  const Eigen::Vector3d base(ps.position_m.x(), ps.position_m.y(), 0);
  const bool moving = ps.speed_mps > 0.05;
  const bool running = ps.speed_mps > 2.5;
  const double phi = 2 * M_PI * ps.gait_cycles;
  const double a_leg = moving ? (running ? 0.65 : 0.38) : 0.0;
  const double a_arm = moving ? (running ? 0.8 : 0.3) : 0.04;
  const double knee_amp = moving ? (running ? 1.3 : 0.45) : 0.0;
  const double elbow = running ? 1.4 : 0.25;
  const double lean = running ? 0.17 : 0.03;
  const Eigen::Vector3d skin = person.skin_bgr;
  const Eigen::Vector3d sock(235, 235, 235), shoe(30, 30, 30);
  Body b;
  b.id = person.id;
  b.ground_xy = ps.position_m;
  const double hip_h = 0.53 * H, thigh = 0.245 * H, shin = 0.255 * H;
  for (int side = -1; side <= 1; side += 2) {
    const double th = side * a_leg * std::sin(phi);
    const double kappa = knee_amp * std::max(0.0, side * std::cos(phi));
    const Eigen::Vector3d hip = base + side * 0.09 * k * l + hip_h * z;
    const Eigen::Vector3d knee = hip + thigh * (std::sin(th) * f - std::cos(th) * z);
    const double sa = th - kappa;
    Eigen::Vector3d foot = knee + shin * (std::sin(sa) * f - std::cos(sa) * z);
    if (foot.z() < 0.04 * k) foot.z() = 0.04 * k;
    b.capsules.push_back({hip, knee, 0.068 * k, team.shorts_bgr, skin, 0.55, false});
    b.capsules.push_back({knee, foot, 0.052 * k, skin, sock, 0.45, false});
    b.capsules.push_back({foot, foot + 0.13 * k * f, 0.04 * k, shoe, shoe, 1.0, false});
  }
  const Eigen::Vector3d lean_off = std::sin(lean) * 0.3 * H * f;
  b.capsules.push_back({base - 0.09 * k * l + 0.55 * H * z, base + 0.09 * k * l + 0.55 * H * z,
                        0.11 * k, team.shorts_bgr, team.shorts_bgr, 1.0, false});
  for (int side = -1; side <= 1; side += 2) {
    b.capsules.push_back({base + side * 0.07 * k * l + 0.6 * H * z,
                          base + side * 0.075 * k * l + 0.77 * H * z + lean_off, 0.105 * k,
                          team.shirt_bgr, team.shirt_bgr, 1.0, false});
  }
  for (int side = -1; side <= 1; side += 2) {
    const Eigen::Vector3d shoulder = base + side * 0.19 * k * l + 0.8 * H * z + lean_off;
    const double ang = -side * a_arm * std::sin(phi);
    const Eigen::Vector3d el = shoulder + 0.17 * H * (std::sin(ang) * f - std::cos(ang) * z);
    const double fa = ang + elbow;
    const Eigen::Vector3d hand = el + 0.16 * H * (std::sin(fa) * f - std::cos(fa) * z);
    b.capsules.push_back({shoulder, el, 0.045 * k, team.shirt_bgr, skin, 0.5, false});
    b.capsules.push_back({el, hand, 0.038 * k, skin, skin, 1.0, false});
  }
  b.capsules.push_back({base + 0.8 * H * z + lean_off, base + 0.88 * H * z + 1.05 * lean_off,
                        0.05 * k, skin, skin, 1.0, false});
  const Eigen::Vector3d head = base + 0.935 * H * z + 1.1 * lean_off;
  b.capsules.push_back({head, head, 0.06 * H, skin, skin, 1.0, true});
  b.box_min = base - Eigen::Vector3d(0.75, 0.75, 0) * k;
  b.box_max = base + Eigen::Vector3d(0.75, 0.75, 0) * k + Eigen::Vector3d(0, 0, H + 0.05);
  return b;
}

namespace {

// The handler's geometry: forward and lateral unit vectors, arm radius and the arms' height above
// the ball centre and lateral offset (the arms touch the ball from above its sides).
struct HandlerFrame {
  Eigen::Vector3d forward, lateral;
  double arm_radius_m = 0.035;
  double arm_dz_m, arm_dy_m;
};

HandlerFrame MakeHandlerFrame(const RobotSpec& robot, double ball_radius_m) {
  HandlerFrame h;
  const double a = robot.heading_deg * M_PI / 180;
  h.forward = Eigen::Vector3d(std::cos(a), std::sin(a), 0);
  h.lateral = Eigen::Vector3d(-std::sin(a), std::cos(a), 0);
  h.arm_dz_m = 0.3 * ball_radius_m;
  const double touch = ball_radius_m + h.arm_radius_m;
  h.arm_dy_m = std::sqrt(touch * touch - h.arm_dz_m * h.arm_dz_m);
  return h;
}

}  // namespace

Eigen::Vector3d HeldBallCentre(const RobotSpec& robot, double ball_radius_m, double time_s) {
  const PathState ps = PathAt(robot.path, time_s);
  const HandlerFrame h = MakeHandlerFrame(robot, ball_radius_m);
  return Eigen::Vector3d(ps.position_m.x(), ps.position_m.y(), ball_radius_m) +
         (robot.radius_m + 0.7 * ball_radius_m) * h.forward;
}

Body RobotBody(const RobotSpec& robot, int index, double time_s, double ball_radius_m) {
  const PathState ps = PathAt(robot.path, time_s);
  Body b;
  b.id = -1 - index;
  b.ground_xy = ps.position_m;
  Cylinder c;
  c.centre_m = ps.position_m;
  c.radius_m = robot.radius_m;
  c.height_m = robot.height_m;
  c.side_bgr = robot.colour_bgr;
  c.top_bgr = 0.5 * robot.colour_bgr + Eigen::Vector3d(60, 60, 60);
  b.cylinders.push_back(c);
  const Eigen::Vector3d r(robot.radius_m, robot.radius_m, 0);
  b.box_min = Eigen::Vector3d(c.centre_m.x(), c.centre_m.y(), 0) - r;
  b.box_max = Eigen::Vector3d(c.centre_m.x(), c.centre_m.y(), robot.height_m) + r;
  if (robot.handler) {
    const HandlerFrame h = MakeHandlerFrame(robot, ball_radius_m);
    const Eigen::Vector3d ball = HeldBallCentre(robot, ball_radius_m, time_s);
    const Eigen::Vector3d arm_bgr = 0.8 * robot.colour_bgr;
    for (int side = -1; side <= 1; side += 2) {
      const Eigen::Vector3d off =
          side * h.arm_dy_m * h.lateral + h.arm_dz_m * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d a =
          ball + off - (0.7 * ball_radius_m + 0.3 * robot.radius_m) * h.forward;
      const Eigen::Vector3d e = ball + off + 0.35 * ball_radius_m * h.forward;
      b.capsules.push_back({a, e, h.arm_radius_m, arm_bgr, arm_bgr, 1.0, false});
      const Eigen::Vector3d rr = Eigen::Vector3d::Constant(h.arm_radius_m);
      b.box_min = b.box_min.cwiseMin(a - rr).cwiseMin(e - rr);
      b.box_max = b.box_max.cwiseMax(a + rr).cwiseMax(e + rr);
    }
  }
  return b;
}

double IntersectCapsule(const Eigen::Vector3d& ro, const Eigen::Vector3d& rd,
                        const Eigen::Vector3d& pa, const Eigen::Vector3d& pb, double ra) {
  const Eigen::Vector3d ba = pb - pa;
  const double baba = ba.dot(ba);
  if (baba < 1e-14) return SphereHit(ro, rd, pa, ra);
  const Eigen::Vector3d oa = ro - pa;
  const double bard = ba.dot(rd), baoa = ba.dot(oa), rdoa = rd.dot(oa), oaoa = oa.dot(oa);
  const double a = baba - bard * bard;
  const double b = baba * rdoa - baoa * bard;
  const double c = baba * oaoa - baoa * baoa - ra * ra * baba;
  const double h = b * b - a * c;
  if (a > 1e-12 && h >= 0) {
    const double t = (-b - std::sqrt(h)) / a;
    const double y = baoa + t * bard;
    if (y > 0 && y < baba) return t;
    return SphereHit(ro, rd, y <= 0 ? pa : pb, ra);
  }
  if (a <= 1e-12) {  // ray parallel to the axis: only the end caps
    const double t1 = SphereHit(ro, rd, pa, ra), t2 = SphereHit(ro, rd, pb, ra);
    if (t1 < 0) return t2;
    if (t2 < 0) return t1;
    return std::min(t1, t2);
  }
  return -1;
}

double IntersectCone(const Eigen::Vector3d& ro, const Eigen::Vector3d& rd,
                     const Eigen::Vector2d& apex_xy, double base_radius, double height,
                     Eigen::Vector3d* normal) {
  const double k = base_radius / height, k2 = k * k;
  const double ox = ro.x() - apex_xy.x(), oy = ro.y() - apex_xy.y(), oz = height - ro.z();
  const double a = rd.x() * rd.x() + rd.y() * rd.y() - k2 * rd.z() * rd.z();
  const double b = 2 * (ox * rd.x() + oy * rd.y() + k2 * oz * rd.z());
  const double c = ox * ox + oy * oy - k2 * oz * oz;
  double roots[2];
  int n = 0;
  if (std::abs(a) < 1e-12) {
    if (std::abs(b) > 1e-12) roots[n++] = -c / b;
  } else {
    const double disc = b * b - 4 * a * c;
    if (disc < 0) return -1;
    const double sq = std::sqrt(disc);
    roots[n++] = (-b - sq) / (2 * a);
    roots[n++] = (-b + sq) / (2 * a);
    if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
  }
  for (int i = 0; i < n; ++i) {
    const double t = roots[i];
    if (t <= 1e-6) continue;
    const Eigen::Vector3d p = ro + t * rd;
    if (p.z() < 0 || p.z() > height) continue;
    if (normal) {
      *normal = Eigen::Vector3d(p.x() - apex_xy.x(), p.y() - apex_xy.y(), k2 * (height - p.z()))
                    .normalized();
    }
    return t;
  }
  return -1;
}

namespace {

double CylinderHit(const Cylinder& c, const Eigen::Vector3d& ro, const Eigen::Vector3d& rd,
                   Eigen::Vector3d* normal, bool* top) {
  double best = -1;
  const double ox = ro.x() - c.centre_m.x(), oy = ro.y() - c.centre_m.y();
  const double a = rd.x() * rd.x() + rd.y() * rd.y();
  if (a > 1e-14) {
    const double b = ox * rd.x() + oy * rd.y();
    const double cc = ox * ox + oy * oy - c.radius_m * c.radius_m;
    const double h = b * b - a * cc;
    if (h >= 0) {
      const double t = (-b - std::sqrt(h)) / a;
      const double z = ro.z() + t * rd.z();
      if (t > 1e-6 && z >= 0 && z <= c.height_m) {
        best = t;
        if (normal) {
          *normal = Eigen::Vector3d(ox + t * rd.x(), oy + t * rd.y(), 0) / c.radius_m;
          *top = false;
        }
      }
    }
  }
  if (std::abs(rd.z()) > 1e-12) {
    const double t = (c.height_m - ro.z()) / rd.z();
    if (t > 1e-6 && (best < 0 || t < best)) {
      const double x = ox + t * rd.x(), y = oy + t * rd.y();
      if (x * x + y * y <= c.radius_m * c.radius_m) {
        best = t;
        if (normal) {
          *normal = Eigen::Vector3d(0, 0, 1);
          *top = true;
        }
      }
    }
  }
  return best;
}

}  // namespace

Hit IntersectBody(const Body& body, const Eigen::Vector3d& ro, const Eigen::Vector3d& rd,
                  double t_min) {
  Hit hit;
  const Capsule* best_c = nullptr;
  for (const Capsule& c : body.capsules) {
    const double t = IntersectCapsule(ro, rd, c.a, c.b, c.radius_m);
    if (t > t_min && (hit.t < 0 || t < hit.t)) {
      hit.t = t;
      best_c = &c;
    }
  }
  for (const Cylinder& cy : body.cylinders) {
    Eigen::Vector3d n = Eigen::Vector3d::UnitZ();  // set by CylinderHit on a hit
    bool top = false;
    const double t = CylinderHit(cy, ro, rd, &n, &top);
    if (t > t_min && (hit.t < 0 || t < hit.t)) {
      hit.t = t;
      best_c = nullptr;
      hit.normal = n;
      hit.colour = top ? cy.top_bgr : cy.side_bgr;
    }
  }
  if (best_c) {
    const Eigen::Vector3d p = ro + hit.t * rd;
    const Eigen::Vector3d ba = best_c->b - best_c->a;
    const double baba = ba.squaredNorm();
    const double h = baba > 0 ? std::clamp((p - best_c->a).dot(ba) / baba, 0.0, 1.0) : 0.0;
    hit.normal = (p - (best_c->a + h * ba)).normalized();
    hit.colour = h < best_c->split ? best_c->colour_a : best_c->colour_b;
    if (best_c->hair && hit.normal.z() > 0.3) hit.colour = Eigen::Vector3d(30, 40, 55);
  }
  return hit;
}

int NumPrimitives(const Body& body) {
  return static_cast<int>(body.capsules.size() + body.cylinders.size());
}

void PrimitiveBounds(const Body& body, int index, Eigen::Vector3d* lo, Eigen::Vector3d* hi) {
  const int nc = static_cast<int>(body.capsules.size());
  if (index < nc) {
    const Capsule& c = body.capsules[index];
    const Eigen::Vector3d r = Eigen::Vector3d::Constant(c.radius_m);
    *lo = c.a.cwiseMin(c.b) - r;
    *hi = c.a.cwiseMax(c.b) + r;
  } else {
    const Cylinder& c = body.cylinders[index - nc];
    *lo = Eigen::Vector3d(c.centre_m.x() - c.radius_m, c.centre_m.y() - c.radius_m, 0);
    *hi = Eigen::Vector3d(c.centre_m.x() + c.radius_m, c.centre_m.y() + c.radius_m, c.height_m);
  }
}

double IntersectPrimitive(const Body& body, int index, const Eigen::Vector3d& ro,
                          const Eigen::Vector3d& rd) {
  const int nc = static_cast<int>(body.capsules.size());
  if (index < nc) {
    const Capsule& c = body.capsules[index];
    return IntersectCapsule(ro, rd, c.a, c.b, c.radius_m);
  }
  return CylinderHit(body.cylinders[index - nc], ro, rd, nullptr, nullptr);
}

Hit ShadePrimitive(const Body& body, int index, const Eigen::Vector3d& ro,
                   const Eigen::Vector3d& rd, double t) {
  Hit hit;
  hit.t = t;
  const int nc = static_cast<int>(body.capsules.size());
  if (index < nc) {
    const Capsule& c = body.capsules[index];
    const Eigen::Vector3d p = ro + t * rd;
    const Eigen::Vector3d ba = c.b - c.a;
    const double baba = ba.squaredNorm();
    const double h = baba > 0 ? std::clamp((p - c.a).dot(ba) / baba, 0.0, 1.0) : 0.0;
    hit.normal = (p - (c.a + h * ba)).normalized();
    hit.colour = h < c.split ? c.colour_a : c.colour_b;
    if (c.hair && hit.normal.z() > 0.3) hit.colour = Eigen::Vector3d(30, 40, 55);
    return hit;
  }
  const Cylinder& cy = body.cylinders[index - nc];
  bool top = false;
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  CylinderHit(cy, ro, rd, &n, &top);
  hit.normal = n;
  hit.colour = top ? cy.top_bgr : cy.side_bgr;
  return hit;
}

bool RayHitsBody(const Body& body, const Eigen::Vector3d& ro, const Eigen::Vector3d& rd) {
  for (const Capsule& c : body.capsules) {
    if (IntersectCapsule(ro, rd, c.a, c.b, c.radius_m) > 1e-6) return true;
  }
  for (const Cylinder& cy : body.cylinders) {
    if (CylinderHit(cy, ro, rd, nullptr, nullptr) > 1e-6) return true;
  }
  return false;
}

}  // namespace fv::synth
