// SceneRenderer: pixel rays and backgrounds per camera, then per frame the boxes of moving objects.
#include <algorithm>
#include <cmath>

#include <ceres/jet.h>
#include <fmt/format.h>

#include "fieldvision/geometry/rigid.h"
#include "fieldvision/synth/ball_physics.h"
#include "fieldvision/synth/figures.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/parallel.h"
#include "fieldvision/util/random.h"

namespace fv::synth {

struct SceneRenderer::CameraData {
  camera::Camera cam;
  Eigen::Vector3d origin;
  std::vector<Eigen::Vector3f> ray;  // unit world direction per pixel; NaN where undefined
  cv::Mat bg;                        // CV_8UC3
  cv::Mat depth;                     // CV_32F, metres along the ray
  std::vector<uint8_t> ground;       // 1 where the background is the ground (takes shadows)
  std::vector<float> vignette;       // brightness factor per pixel
  double pixel_angle = 0.0;          // radians per pixel near the centre
};

// One sub-exposure position of the ball: centre and turn (body to world).
struct BallSample {
  Eigen::Vector3d centre;
  Eigen::Matrix3d orientation;
};

namespace {

using Vec3 = Eigen::Vector3d;

constexpr double kInf = std::numeric_limits<double>::infinity();

uint64_t SplitMix(uint64_t& x) {
  uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double Hash2(int x, int y, uint32_t salt = 0) {
  uint32_t h = static_cast<uint32_t>(x) * 374761393u + static_cast<uint32_t>(y) * 668265263u +
               salt * 2246822519u;
  h = (h ^ (h >> 13)) * 1274126177u;
  h ^= h >> 16;
  return h / 4294967296.0;
}

double ValueNoise(double x, double y, uint32_t salt = 0) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  double tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);
  ty = ty * ty * (3 - 2 * ty);
  const double a = Hash2(ix, iy, salt), b = Hash2(ix + 1, iy, salt);
  const double c = Hash2(ix, iy + 1, salt), d = Hash2(ix + 1, iy + 1, salt);
  return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty;
}

Vec3 Clamp255(const Vec3& c) { return c.cwiseMax(0.0).cwiseMin(255.0); }

// Brightness factor of a surface at cos(angle to the light) ndl: the fixed shading (base + slope
// max(0, ndl)) or, with an ambient share, ambient + (1 - ambient) max(0, ndl).
double Lambert(const LightingSpec& l, double ndl, double base, double slope) {
  const double lit = std::max(0.0, ndl);
  return l.ambient >= 0 ? l.ambient + (1 - l.ambient) * lit : base + slope * lit;
}

camera::Camera MakeCamera(const CameraSpec& s, int index) {
  camera::Camera c;
  if (s.fx > 0) {
    c.width = s.width;
    c.height = s.height;
    c.fx = s.fx;
    c.fy = s.fy;
    c.cx = 0.5 * (s.width - 1);
    c.cy = 0.5 * (s.height - 1);
  } else {
    c = camera::Camera::FromFov(s.width, s.height, s.hfov_deg);
  }
  c.name = s.name;
  c.distortion = s.distortion;
  c.has_pose = true;
  c.cam_from_world = s.has_rvec_tvec ? geometry::Rigid3d::FromRvecTvec(s.rvec, s.tvec)
                                     : geometry::Rigid3d::LookAt(s.position_m, s.look_at_m);
  c.notes["source"] = "fieldvision synth";
  c.Check(fmt::format("cameras[{}]", index));
  return c;
}

// The world ray of every pixel: exact undistortion seeded from a coarse grid, refined by Newton.
std::vector<Eigen::Vector3f> PixelRays(const camera::Camera& cam) {
  const int w = cam.width, h = cam.height;
  std::vector<Eigen::Vector3f> rays(static_cast<size_t>(w) * h);
  const Eigen::Matrix3d world_from_cam = cam.cam_from_world.rotation.transpose();
  bool distorted = false;
  for (double d : cam.distortion) distorted = distorted || d != 0.0;
  const auto intr = cam.IntrinsicsBlock();
  const double* dist = intr.data() + 4;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto store = [&](int u, int v, double x, double y) {
    const Eigen::Vector3d d = (world_from_cam * Eigen::Vector3d(x, y, 1.0)).normalized();
    rays[static_cast<size_t>(v) * w + u] = d.cast<float>();
  };
  if (!distorted) {
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) store(u, v, (u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy);
    }
    return rays;
  }
  const int step = 16;
  const int gw = (w - 1) / step + 2, gh = (h - 1) / step + 2;
  std::vector<Eigen::Vector2d> grid(static_cast<size_t>(gw) * gh);
  std::vector<uint8_t> grid_ok(grid.size());
  for (int j = 0; j < gh; ++j) {
    for (int i = 0; i < gw; ++i) {
      const auto x = cam.Undistort(Eigen::Vector2d(i * step, j * step));
      grid_ok[j * gw + i] = x.has_value();
      if (x) grid[j * gw + i] = *x;
    }
  }
  using Jet = ceres::Jet<double, 2>;
  std::array<Jet, camera::kNumDistortion> dj;
  for (int i = 0; i < camera::kNumDistortion; ++i) dj[i] = Jet(dist[i]);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector2d target((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy);
      const int i = u / step, j = v / step;
      const double a = (u - i * step) / static_cast<double>(step);
      const double b = (v - j * step) / static_cast<double>(step);
      const size_t k00 = j * gw + i, k10 = k00 + 1, k01 = k00 + gw, k11 = k01 + 1;
      bool converged = false;
      Eigen::Vector2d x;
      if (grid_ok[k00] && grid_ok[k10] && grid_ok[k01] && grid_ok[k11]) {
        x = (1 - b) * ((1 - a) * grid[k00] + a * grid[k10]) +
            b * ((1 - a) * grid[k01] + a * grid[k11]);
        for (int it = 0; it < 6; ++it) {
          Jet xd, yd;
          camera::DistortNormalized(dj.data(), Jet(x.x(), 0), Jet(x.y(), 1), &xd, &yd);
          const Eigen::Vector2d r(xd.a - target.x(), yd.a - target.y());
          if (std::abs(r.x() * cam.fx) + std::abs(r.y() * cam.fy) < 1e-9) {
            converged = true;
            break;
          }
          Eigen::Matrix2d jm;
          jm << xd.v[0], xd.v[1], yd.v[0], yd.v[1];
          const double det = jm.determinant();
          if (!std::isfinite(det) || std::abs(det) < 1e-12) break;
          x -= jm.inverse() * r;
        }
      }
      if (!converged) {
        const auto xo = cam.Undistort(Eigen::Vector2d(u, v));
        if (!xo) {
          rays[static_cast<size_t>(v) * w + u] = Eigen::Vector3f(nan, nan, nan);
          continue;
        }
        x = *xo;
      }
      store(u, v, x.x(), x.y());
    }
  }
  return rays;
}

// The static world seen by the background pass.
struct StaticWorld {
  const field::FieldModel* field = nullptr;
  double hl = 0, hw = 0;  // half extents with the surround (walls stand there)
  double wall_h = 2.6;
  double stripe_w = 1.5;
  bool grass = true;
  Vec3 light;
  const LightingSpec* lighting = nullptr;
  // Coarse top-view map of the signed distance to paint (for skipping far pixels).
  double map_res = 0.05;
  int map_w = 0, map_h = 0;
  std::vector<float> paint_map;
  struct Bar {
    Vec3 a, b;
    double r;
    Vec3 colour;
  };
  std::vector<Bar> bars;  // goal frames
  std::vector<ConeSpec> cones;

  double CoarsePaint(double x, double y) const {
    const int i = static_cast<int>(std::lround((x + hl) / map_res));
    const int j = static_cast<int>(std::lround((y + hw) / map_res));
    if (i < 0 || j < 0 || i >= map_w || j >= map_h) return 1e3;
    return paint_map[static_cast<size_t>(j) * map_w + i];
  }

  Vec3 Ground(double x, double y, double fp) const {
    const field::FieldModel& f = *field;
    const bool playing = std::abs(x) <= 0.5 * f.length_m && std::abs(y) <= 0.5 * f.width_m;
    const double fine = std::clamp(1.0 - fp / 0.06, 0.0, 1.0);
    Vec3 c;
    if (grass) {
      c = Vec3(48, 128, 58);
      if (playing) {
        const int band = static_cast<int>(std::floor((x + 0.5 * f.length_m) / stripe_w));
        c *= (band % 2 == 0) ? 1.08 : 0.93;
      } else {
        c *= 0.9;
      }
      const double m = 1.0 + 0.10 * (ValueNoise(x / 0.9, y / 0.9, 1) - 0.5) +
                       0.12 * fine * (ValueNoise(x / 0.05, y / 0.05, 2) - 0.5);
      c *= m;
    } else {
      if (playing) {
        const int plank = static_cast<int>(std::floor(y / 0.12));
        const double pl =
            0.92 + 0.16 * Hash2(plank, static_cast<int>(std::floor(x / 2.4 + 0.37 * plank)), 3);
        c = Vec3(105, 155, 205) * pl;
      } else {
        c = Vec3(150, 105, 55);
      }
      c *= 1.0 + 0.06 * (ValueNoise(x / 0.7, y / 0.7, 4) - 0.5);
    }
    return c;
  }

  Vec3 Wall(double s, double z) const {
    if (z < 0.9) {
      static const Vec3 kPalette[6] = {Vec3(170, 60, 20),  Vec3(30, 30, 190), Vec3(235, 235, 235),
                                       Vec3(20, 170, 230), Vec3(60, 60, 60),  Vec3(40, 140, 40)};
      const int panel = static_cast<int>(std::floor(s / 4.0));
      const Vec3 bgc = kPalette[static_cast<int>(Hash2(panel, 7, 5) * 6) % 6];
      const double in = s - 4.0 * panel;
      const bool text = z > 0.3 && z < 0.62 && in > 0.5 && in < 3.5 &&
                        Hash2(static_cast<int>(std::floor(in / 0.22)), panel, 6) > 0.35;
      if (z < 0.05) return Vec3(40, 40, 40);
      return text ? Vec3(255, 255, 255) - 0.7 * bgc : bgc;
    }
    // Stands with spectators: rows every 0.45 m, a person-sized cell of random colour.
    const int row = static_cast<int>(std::floor((z - 0.9) / 0.45));
    const int col = static_cast<int>(std::floor(s / 0.5));
    const double rz = (z - 0.9) - 0.45 * row;
    if (rz < 0.08) return Vec3(95, 95, 100);
    const double hsh = Hash2(col, row, 9);
    if (hsh < 0.35) return Vec3(130, 130, 135);
    const Vec3 shirt(255 * Hash2(col, row, 10), 255 * Hash2(col, row, 11),
                     255 * Hash2(col, row, 12));
    return rz > 0.32 ? Vec3(120, 150, 190) : 0.55 * shirt + Vec3(50, 50, 50);
  }

  Vec3 Sky(const Vec3& d) const {
    const double e = std::clamp(d.z(), 0.0, 1.0);
    return Vec3(225, 210, 195) * (1 - e) + Vec3(235, 190, 150) * e;
  }

  double Shade(const Vec3& n) const { return Lambert(*lighting, n.dot(light), 0.55, 0.5); }
};

StaticWorld MakeStaticWorld(const field::FieldModel& f, const SceneSpec& spec) {
  StaticWorld w;
  w.field = &f;
  w.hl = f.HalfLengthWithSurround();
  w.hw = f.HalfWidthWithSurround();
  w.grass = f.surface == "grass";
  w.stripe_w = f.length_m / std::clamp(std::round(f.length_m / 1.5), 6.0, 24.0);
  w.light = spec.lighting.Direction();
  w.lighting = &spec.lighting;
  w.map_w = static_cast<int>(std::ceil(2 * w.hl / w.map_res)) + 1;
  w.map_h = static_cast<int>(std::ceil(2 * w.hw / w.map_res)) + 1;
  w.paint_map.resize(static_cast<size_t>(w.map_w) * w.map_h);
  for (int j = 0; j < w.map_h; ++j) {
    for (int i = 0; i < w.map_w; ++i) {
      w.paint_map[static_cast<size_t>(j) * w.map_w + i] = static_cast<float>(
          f.DistanceToPaint(Eigen::Vector2d(i * w.map_res - w.hl, j * w.map_res - w.hw)));
    }
  }
  const Vec3 white(240, 240, 240), grey(200, 200, 200);
  for (const field::FieldGoal& g : f.goals) {
    const double r = 0.5 * g.post_width_m;
    const double x = g.line_x_m + g.side * r;
    const double xb = g.line_x_m + g.side * (g.depth_m + r);
    const double y0 = g.y_min_m - r, y1 = g.y_max_m + r, top = g.height_m + r;
    w.bars.push_back({Vec3(x, y0, 0), Vec3(x, y0, top), r, white});
    w.bars.push_back({Vec3(x, y1, 0), Vec3(x, y1, top), r, white});
    w.bars.push_back({Vec3(x, y0, top), Vec3(x, y1, top), r, white});
    const double rb = std::min(r, 0.025);
    w.bars.push_back({Vec3(x, y0, top), Vec3(xb, y0, 0.3 * top), rb, grey});
    w.bars.push_back({Vec3(x, y1, top), Vec3(xb, y1, 0.3 * top), rb, grey});
    w.bars.push_back({Vec3(xb, y0, 0.3 * top), Vec3(xb, y0, 0), rb, grey});
    w.bars.push_back({Vec3(xb, y1, 0.3 * top), Vec3(xb, y1, 0), rb, grey});
    w.bars.push_back({Vec3(xb, y0, rb), Vec3(xb, y1, rb), rb, grey});
    w.bars.push_back({Vec3(xb, y0, 0.3 * top), Vec3(xb, y1, 0.3 * top), rb, grey});
  }
  w.cones = spec.cones;
  return w;
}

// The static world along every pixel's ray: colour, depth, ground flag and (on the ground) the
// signed distance to the nearest paint.
void CastBackground(const StaticWorld& world, SceneRenderer::CameraData& cd,
                    std::vector<float>& paint, std::vector<Vec3>& colour) {
  const int w = cd.cam.width, h = cd.cam.height;
  const Vec3 o = cd.origin;
  const bool inside = std::abs(o.x()) < world.hl && std::abs(o.y()) < world.hw;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      const Eigen::Vector3f df = cd.ray[i];
      if (!df.allFinite()) {
        colour[i] = Vec3(0, 0, 0);
        cd.depth.at<float>(v, u) = std::numeric_limits<float>::infinity();
        continue;
      }
      const Vec3 d = df.cast<double>();
      double best = kInf;
      Vec3 c = world.Sky(d);
      int kind = 0;  // 0 sky, 1 ground, 2 wall/object
      // Walls: one-sided, seen from inside.
      if (inside) {
        for (int axis = 0; axis < 2; ++axis) {
          const double half = axis == 0 ? world.hl : world.hw;
          const double dd = d[axis];
          if (std::abs(dd) < 1e-12) continue;
          const double plane = dd > 0 ? half : -half;
          const double t = (plane - o[axis]) / dd;
          if (t <= 0 || t >= best) continue;
          const Vec3 p = o + t * d;
          const double other = axis == 0 ? world.hw : world.hl;
          if (p.z() < 0 || p.z() > world.wall_h || std::abs(p[1 - axis]) > other) continue;
          best = t;
          kind = 2;
          const double s = p[1 - axis] + (axis == 0 ? 100.0 : 0.0) + (plane > 0 ? 50.0 : 0.0);
          c = world.Wall(s, p.z()) * (axis == 0 ? 0.92 : 1.0);
        }
      }
      if (d.z() < 0) {
        const double t = -o.z() / d.z();
        if (t > 0 && t < best) {
          const Vec3 p = o + t * d;
          best = t;
          kind = 1;
          if (std::abs(p.x()) <= world.hl && std::abs(p.y()) <= world.hw) {
            const double fp = t * cd.pixel_angle / std::max(std::abs(d.z()), 0.05);
            c = world.Ground(p.x(), p.y(), fp);
            const double coarse = world.CoarsePaint(p.x(), p.y());
            if (coarse < 0.05 + std::max(0.3, 4 * fp)) {
              paint[i] = static_cast<float>(world.field->DistanceToPaint(p.head<2>()));
            } else {
              paint[i] = static_cast<float>(coarse);
            }
          } else {
            c = Vec3(105, 110, 115);
          }
        }
      }
      for (const auto& bar : world.bars) {
        const double t = IntersectCapsule(o, d, bar.a, bar.b, bar.r);
        if (t > 0 && t < best) {
          best = t;
          kind = 2;
          const Vec3 p = o + t * d;
          const Vec3 ba = bar.b - bar.a;
          const double s = std::clamp((p - bar.a).dot(ba) / ba.squaredNorm(), 0.0, 1.0);
          c = bar.colour * world.Shade((p - (bar.a + s * ba)).normalized());
        }
      }
      for (const auto& cone : world.cones) {
        Vec3 n = Vec3::UnitZ();
        const double t =
            IntersectCone(o, d, cone.position_m, cone.base_radius_m, cone.height_m, &n);
        if (t > 0 && t < best) {
          best = t;
          kind = 2;
          c = cone.colour_bgr * world.Shade(n);
        }
      }
      colour[i] = c;
      cd.depth.at<float>(v, u) = static_cast<float>(best);
      cd.ground[i] = kind == 1;
    }
  }
}

// Painted lines blended into the ground colours.
void PaintLines(const StaticWorld& world, const SceneRenderer::CameraData& cd,
                const std::vector<float>& paint, std::vector<Vec3>& colour) {
  const int w = cd.cam.width, h = cd.cam.height;
  const double line_half = 0.5 * world.field->line_width_m;
  // Paint coverage: the overlap of the pixel with the line across it, in pixel units from the
  // signed distance and its screen-space rate of change (largest one-sided difference).
  const Vec3 paint_colour(232, 238, 238);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      if (!cd.ground[i] || paint[i] > 2.0f) continue;
      const double d0 = paint[i];
      auto rate = [&](int du, int dv) {
        double g = 0;
        for (int sgn = -1; sgn <= 1; sgn += 2) {
          const int uu = u + sgn * du, vv = v + sgn * dv;
          if (uu < 0 || vv < 0 || uu >= w || vv >= h) continue;
          const size_t j = static_cast<size_t>(vv) * w + uu;
          if (!cd.ground[j]) continue;
          g = std::max(g, std::abs(paint[j] - d0));
        }
        return g;
      };
      const double gx = rate(1, 0), gy = rate(0, 1);
      double g = std::sqrt(gx * gx + gy * gy);
      if (g < 1e-6) g = 1e-6;
      const double a = line_half / g;                 // half width in pixels
      const double x = std::abs(d0 + line_half) / g;  // distance from the centreline in pixels
      const double cov = std::clamp(std::min(x + 0.5, a) - std::max(x - 0.5, -a), 0.0, 1.0);
      if (cov > 0) colour[i] = (1 - cov) * colour[i] + cov * paint_colour;
    }
  }
}

void RenderBackground(const StaticWorld& world, SceneRenderer::CameraData& cd,
                      const SceneSpec& spec) {
  const camera::Camera& cam = cd.cam;
  const int w = cam.width, h = cam.height;
  cd.bg.create(h, w, CV_8UC3);
  cd.depth.create(h, w, CV_32F);
  cd.ground.assign(static_cast<size_t>(w) * h, 0);
  std::vector<float> paint(static_cast<size_t>(w) * h, 1e3f);
  std::vector<Vec3> colour(static_cast<size_t>(w) * h);
  CastBackground(world, cd, paint, colour);
  PaintLines(world, cd, paint, colour);
  for (int v = 0; v < h; ++v) {
    auto* row = cd.bg.ptr<cv::Vec3b>(v);
    for (int u = 0; u < w; ++u) {
      const Vec3 c = Clamp255(colour[static_cast<size_t>(v) * w + u]);
      row[u] = cv::Vec3b(static_cast<uint8_t>(std::lround(c[0])),
                         static_cast<uint8_t>(std::lround(c[1])),
                         static_cast<uint8_t>(std::lround(c[2])));
    }
  }
  cd.vignette.resize(static_cast<size_t>(w) * h);
  const double rmax2 = cam.cx * cam.cx + cam.cy * cam.cy;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const double r2 = ((u - cam.cx) * (u - cam.cx) + (v - cam.cy) * (v - cam.cy)) / rmax2;
      cd.vignette[static_cast<size_t>(v) * w + u] =
          static_cast<float>(1.0 - spec.lighting.vignetting * r2);
    }
  }
}

// Image box (clipped) of a world box; empty when entirely behind the camera.
cv::Rect ProjectBox(const camera::Camera& cam, const Vec3& lo, const Vec3& hi,
                    double margin_px = 2) {
  double umin = kInf, vmin = kInf, umax = -kInf, vmax = -kInf;
  int behind = 0;
  for (int k = 0; k < 8; ++k) {
    const Vec3 p((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
    const Vec3 pc = cam.cam_from_world * p;
    if (pc.z() < 0.05) {
      ++behind;
      continue;
    }
    const auto uv = cam.ProjectFromCamera(pc);
    const double lim = 3.0 * std::max(cam.width, cam.height);
    if (!uv || !uv->allFinite() || std::abs(uv->x()) > lim || std::abs(uv->y()) > lim) {
      ++behind;
      continue;
    }
    umin = std::min(umin, uv->x());
    umax = std::max(umax, uv->x());
    vmin = std::min(vmin, uv->y());
    vmax = std::max(vmax, uv->y());
  }
  if (behind == 8) return {};
  if (behind > 0) return {0, 0, cam.width, cam.height};
  const int x0 = std::max(0, static_cast<int>(std::floor(umin - margin_px)));
  const int y0 = std::max(0, static_cast<int>(std::floor(vmin - margin_px)));
  const int x1 = std::min(cam.width, static_cast<int>(std::ceil(umax + margin_px)) + 1);
  const int y1 = std::min(cam.height, static_cast<int>(std::ceil(vmax + margin_px)) + 1);
  if (x1 <= x0 || y1 <= y0) return {};
  return {x0, y0, x1 - x0, y1 - y0};
}

// Projected centre and apparent radius of a sphere (from its silhouette circle).
bool ProjectSphere(const camera::Camera& cam, const Vec3& c, double r, Eigen::Vector2d* uv,
                   double* radius_px) {
  const Vec3 o = cam.CentreInWorld();
  const Vec3 dv = c - o;
  const double dist = dv.norm();
  const auto p = cam.Project(c);
  if (!p || dist <= r * 1.0001) return false;
  *uv = *p;
  const Vec3 n = dv / dist;
  Vec3 e1 = n.cross(Vec3(0, 0, 1));
  if (e1.norm() < 1e-6) e1 = n.cross(Vec3(1, 0, 0));
  e1.normalize();
  const Vec3 e2 = n.cross(e1);
  const Vec3 centre = c - (r * r / dist) * n;
  const double rho = r * std::sqrt(1.0 - (r * r) / (dist * dist));
  double sum = 0;
  int cnt = 0;
  for (int k = 0; k < 8; ++k) {
    const double a = k * M_PI / 4;
    const auto q = cam.Project(centre + rho * (std::cos(a) * e1 + std::sin(a) * e2));
    if (q) {
      sum += (*q - *p).norm();
      ++cnt;
    }
  }
  *radius_px = cnt > 0 ? sum / cnt : 0.0;
  return cnt > 0;
}

}  // namespace

SceneRenderer::SceneRenderer(const SceneSpec& spec) : spec_(spec) {
  spec_.Check();
  field_ = field::LoadField(spec_.field);
  for (size_t i = 0; i < spec_.cameras.size(); ++i) {
    cameras_.push_back(MakeCamera(spec_.cameras[i], static_cast<int>(i)));
  }
  if (spec_.ball.enabled) {
    trajectory_ = std::make_unique<BallTrajectory>(spec_.ball, spec_.duration_s());
  }
  util::Rng rng(spec_.seed * 6364136223846793005ULL + 1442695040888963407ULL);
  noise_table_.resize(65536);
  for (auto& n : noise_table_) {
    n = static_cast<int16_t>(
        std::lround(std::clamp(rng.Normal(0, spec_.noise_sigma), -127.0, 127.0)));
  }
  const StaticWorld world = MakeStaticWorld(field_, spec_);
  data_.resize(cameras_.size());
  util::ParallelFor(cameras_.size(), [&](size_t i) {
    auto cd = std::make_unique<CameraData>();
    cd->cam = cameras_[i];
    cd->origin = cd->cam.CentreInWorld();
    cd->pixel_angle = 1.0 / std::sqrt(cd->cam.fx * cd->cam.fy);
    cd->ray = PixelRays(cd->cam);
    RenderBackground(world, *cd, spec_);
    data_[i] = std::move(cd);
  });
}

SceneRenderer::~SceneRenderer() = default;

Eigen::Vector3d SceneRenderer::BallAt(double time_s) const {
  FV_REQUIRE(spec_.ball.enabled, "BallAt: the scene has no ball");
  if (spec_.ball.held_by >= 0) {
    return HeldBallCentre(spec_.robots[spec_.ball.held_by], spec_.ball.radius_m(), time_s);
  }
  if (!spec_.ball.placements.empty()) {
    const long frame = std::lround(std::floor(time_s * spec_.fps + 0.5));
    const long idx = std::clamp<long>(frame / spec_.ball.hold_frames, 0,
                                      static_cast<long>(spec_.ball.placements.size()) - 1);
    return spec_.ball.placements[idx];
  }
  return trajectory_->PositionAt(time_s);
}

Eigen::Matrix3d SceneRenderer::BallOrientation(double time_s) const {
  const BallSpec& ball = spec_.ball;
  Eigen::Matrix3d r = geometry::RotationFromRvec(ball.orientation_rvec);
  if (!ball.placements.empty()) {
    // A seeded turn per placement, so that each shows another side of the print.
    const long frame = std::lround(std::floor(time_s * spec_.fps + 0.5));
    const long idx = std::clamp<long>(frame / ball.hold_frames, 0,
                                      static_cast<long>(ball.placements.size()) - 1);
    uint64_t state = spec_.seed * 0xD1B54A32D192ED03ULL + static_cast<uint64_t>(idx);
    const double z = 2.0 * (SplitMix(state) >> 11) * 0x1.0p-53 - 1.0;
    const double az = 2 * M_PI * (SplitMix(state) >> 11) * 0x1.0p-53;
    const double angle = M_PI * (SplitMix(state) >> 11) * 0x1.0p-53;
    const double rho = std::sqrt(std::max(0.0, 1 - z * z));
    return geometry::RotationFromRvec(angle * Vec3(rho * std::cos(az), rho * std::sin(az), z)) * r;
  }
  // Kicks: each spins the ball from its time until the next kick.
  std::vector<KickSpec> kicks = ball.kicks;
  std::stable_sort(kicks.begin(), kicks.end(),
                   [](const KickSpec& a, const KickSpec& b) { return a.time_s < b.time_s; });
  for (size_t k = 0; k < kicks.size() && kicks[k].time_s < time_s; ++k) {
    const double end = k + 1 < kicks.size() ? std::min(time_s, kicks[k + 1].time_s) : time_s;
    r = geometry::RotationFromRvec(kicks[k].spin_radps * (end - kicks[k].time_s)) * r;
  }
  return r;
}

std::vector<BallSample> SceneRenderer::BallSamples(int camera, double t) const {
  const camera::Camera& cam = cameras_[camera];
  const bool patterned = spec_.ball.pattern != "none";
  // Sub-exposure samples: about one per half pixel of image motion.
  const double e = spec_.exposure_s;
  int K = 1;
  if (e > 0) {
    const auto p0 = cam.Project(BallAt(t - 0.5 * e));
    const auto p1 = cam.Project(BallAt(t + 0.5 * e));
    if (p0 && p1) {
      K = std::clamp(static_cast<int>(std::ceil((*p1 - *p0).norm() / 0.5)) + 1, 1, 48);
    }
  }
  std::vector<BallSample> out;
  for (int k = 0; k < K; ++k) {
    const double tk = K == 1 ? t : t + e * ((k + 0.5) / K - 0.5);
    out.push_back({BallAt(tk), patterned ? BallOrientation(tk) : Eigen::Matrix3d::Identity()});
  }
  return out;
}

const std::vector<Flight>& SceneRenderer::Flights() const {
  static const std::vector<Flight> kNone;
  return trajectory_ ? trajectory_->flights() : kNone;
}

const cv::Mat& SceneRenderer::Background(int camera) const {
  FV_REQUIRE(camera >= 0 && camera < static_cast<int>(data_.size()), "camera {} out of range",
             camera);
  return data_[camera]->bg;
}

const cv::Mat& SceneRenderer::BackgroundDepth(int camera) const {
  FV_REQUIRE(camera >= 0 && camera < static_cast<int>(data_.size()), "camera {} out of range",
             camera);
  return data_[camera]->depth;
}

cv::Mat SceneRenderer::RenderCamera(int camera, int frame, CameraFrameStats* stats) const {
  return RenderInternal(camera, frame, stats, true);
}

CameraFrameStats SceneRenderer::CameraTruth(int camera, int frame) const {
  CameraFrameStats s;
  RenderInternal(camera, frame, &s, false);
  return s;
}

namespace {

// The 12 pentagons of a classic football (truncated icosahedron): per pentagon its centre and the
// 5 outward edge normals in the gnomonic plane at the centre; inradius there (tangent units).
struct Pentagons {
  std::array<Vec3, 12> centre;
  std::array<std::array<Vec3, 5>, 12> edge;
  double inradius = 0;
  double cos_reach = 0;  // points with x . centre below this are outside
};

const Pentagons& FootballPentagons() {
  static const Pentagons kPentagons = [] {
    Pentagons out;
    const double phi = 0.5 * (1 + std::sqrt(5.0));
    int k = 0;
    for (int s1 = -1; s1 <= 1; s1 += 2) {
      for (int s2 = -1; s2 <= 1; s2 += 2) {
        out.centre[k++] = Vec3(0, s1, s2 * phi).normalized();
        out.centre[k++] = Vec3(s1, s2 * phi, 0).normalized();
        out.centre[k++] = Vec3(s2 * phi, 0, s1).normalized();
      }
    }
    // Pentagon vertices point at the neighbouring icosahedron vertices; angular circumradius of
    // the truncated icosahedron's pentagons: asin(0.8507 / 2.4782).
    const double rho = std::asin(0.85065 / 2.47802);
    out.inradius = std::tan(rho) * std::cos(M_PI / 5);
    out.cos_reach = std::cos(rho) - 1e-3;
    const double nb = 1.0 / std::sqrt(5.0);  // cos of the icosahedron's edge angle
    for (int i = 0; i < 12; ++i) {
      const Vec3& c = out.centre[i];
      auto tangent = [&](const Vec3& n) { return (n / n.dot(c) - c).normalized(); };
      std::vector<int> ns;
      for (int j = 0; j < 12; ++j) {
        if (j != i && std::abs(out.centre[j].dot(c) - nb) < 1e-6) ns.push_back(j);
      }
      int e = 0;
      for (size_t a = 0; a < ns.size(); ++a) {
        for (size_t b = a + 1; b < ns.size(); ++b) {
          if (std::abs(out.centre[ns[a]].dot(out.centre[ns[b]]) - nb) > 1e-6) continue;
          out.edge[i][e++ % 5] =
              (tangent(out.centre[ns[a]]) + tangent(out.centre[ns[b]])).normalized();
        }
      }
    }
    return out;
  }();
  return kPentagons;
}

// Share of the pattern's print at a point x (unit vector in the ball's frame); px: a pixel's
// angular size on the ball (radians), for a soft, anti-aliased edge.
double PatternCover(const std::string& pattern, const Vec3& x, double px) {
  double sd = 1.0;  // signed distance to the print (radians, negative inside)
  if (pattern == "pentagons") {
    const Pentagons& p = FootballPentagons();
    for (int i = 0; i < 12; ++i) {
      const double cd = x.dot(p.centre[i]);
      if (cd < p.cos_reach - 0.1) continue;
      const Vec3 q = x / cd - p.centre[i];
      double d = -kInf;
      for (const Vec3& m : p.edge[i]) d = std::max(d, q.dot(m) - p.inradius);
      sd = std::min(sd, d);
    }
  } else if (pattern == "print") {
    // Three wavy bands around tilted axes.
    static const std::array<Vec3, 3> kAxes = {Vec3(0.2, 0.1, 1.0).normalized(),
                                              Vec3(1.0, -0.3, 0.15).normalized(),
                                              Vec3(-0.25, 1.0, 0.35).normalized()};
    for (int k = 0; k < 3; ++k) {
      const Vec3& a = kAxes[k];
      const Vec3 e1 = a.cross(k == 0 ? Vec3::UnitX() : Vec3::UnitZ()).normalized();
      const Vec3 e2 = a.cross(e1);
      const double lon = std::atan2(x.dot(e2), x.dot(e1));
      const double lat = std::asin(std::clamp(x.dot(a), -1.0, 1.0));
      sd = std::min(sd, std::abs(lat + 0.2 * std::sin(3 * lon + k)) - 0.085);
    }
  } else {
    return 0.0;
  }
  return std::clamp(0.5 - sd / std::max(px, 1e-6), 0.0, 1.0);
}

// One camera's frame while it is rendered: the image and depth so far and what the stages share.
struct FrameCanvas {
  const SceneRenderer::CameraData& cd;
  const LightingSpec& lighting;
  Vec3 light;
  cv::Mat img, depth;
  Vec3 Ray(int u, int v) const {
    return cd.ray[static_cast<size_t>(v) * cd.cam.width + u].cast<double>();
  }
};

// What DrawBodies found per body: image box, pixels hit (occluded or not), their bounding box, and
// per pixel the visible body (index + 1).
struct BodyRaster {
  std::vector<uint16_t> id;
  std::vector<cv::Rect> boxes;
  std::vector<long> hits_all;
  std::vector<cv::Rect> hit_bbox;
};

// Darkens the ground where bodies and the ball (soft-edged) block the light.
void CastShadows(FrameCanvas& fc, const std::vector<Body>& bodies, bool has_ball,
                 const Vec3& ball_mid, double r_ball) {
  const auto& cd = fc.cd;
  const int w = cd.cam.width, h = cd.cam.height;
  const Vec3& light = fc.light;
  const Vec3 o = cd.origin;
  // Light lost in a full shadow: fixed, or all but the ambient share of the lit ground.
  const double lost =
      fc.lighting.ambient >= 0
          ? 1.0 - fc.lighting.ambient /
                      (fc.lighting.ambient + (1 - fc.lighting.ambient) * std::max(light.z(), 1e-3))
          : 0.42;
  std::vector<uint8_t> shadowed;
  auto shade_box = [&](const Vec3& lo, const Vec3& hi, auto&& occlusion) {
    Vec3 slo = lo, shi = hi;
    for (int k = 0; k < 8; ++k) {
      const Vec3 p((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
      const Vec3 g = p - (p.z() / light.z()) * light;
      slo = slo.cwiseMin(g);
      shi = shi.cwiseMax(g);
    }
    slo.z() = 0;
    const cv::Rect box = ProjectBox(cd.cam, slo, shi);
    if (box.empty()) return;
    if (shadowed.empty()) shadowed.assign(static_cast<size_t>(w) * h, 0);
    for (int v = box.y; v < box.y + box.height; ++v) {
      auto* row = fc.img.ptr<cv::Vec3b>(v);
      const float* drow = fc.depth.ptr<float>(v);
      for (int u = box.x; u < box.x + box.width; ++u) {
        const size_t i = static_cast<size_t>(v) * w + u;
        if (!cd.ground[i] || shadowed[i]) continue;
        const Vec3 p = o + static_cast<double>(drow[u]) * fc.Ray(u, v);
        const double s = occlusion(Vec3(p.x(), p.y(), 1e-4));
        if (s <= 0) continue;
        const double f = 1.0 - lost * s;
        for (int ch = 0; ch < 3; ++ch) row[u][ch] = static_cast<uint8_t>(row[u][ch] * f);
        if (s >= 1) shadowed[i] = 1;
      }
    }
  };
  for (const Body& b : bodies) {
    // Ground boxes of each primitive's shadow, to test only the primitives that can shade.
    const int np = NumPrimitives(b);
    std::vector<Eigen::Vector4d> sb(np);
    for (int q = 0; q < np; ++q) {
      Vec3 lo, hi;
      PrimitiveBounds(b, q, &lo, &hi);
      Eigen::Vector4d box(kInf, kInf, -kInf, -kInf);
      for (int k = 0; k < 8; ++k) {
        const Vec3 p((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(),
                     (k & 4) ? hi.z() : lo.z());
        const Vec3 g = p - (p.z() / light.z()) * light;
        box = Eigen::Vector4d(std::min(box[0], g.x()), std::min(box[1], g.y()),
                              std::max(box[2], g.x()), std::max(box[3], g.y()));
      }
      sb[q] = box;
    }
    shade_box(b.box_min, b.box_max, [&](const Vec3& p) {
      for (int q = 0; q < np; ++q) {
        if (p.x() < sb[q][0] || p.y() < sb[q][1] || p.x() > sb[q][2] || p.y() > sb[q][3]) {
          continue;
        }
        if (IntersectPrimitive(b, q, p, light) > 1e-6) return 1.0;
      }
      return 0.0;
    });
  }
  if (has_ball && ball_mid.z() < 8.0) {
    const Vec3 rr(r_ball, r_ball, r_ball);
    shade_box(ball_mid - rr, ball_mid + rr, [&](const Vec3& p) {
      const Vec3 q = ball_mid - p;
      const double along = q.dot(light);
      if (along <= 0) return 0.0;
      const double dist = (q - along * light).norm();
      return std::clamp((1.1 * r_ball - dist) / (0.3 * r_ball), 0.0, 1.0);
    });
  }
}

// Opaque bodies with a depth test (shaded when want_image), and the ids for the truth.
BodyRaster DrawBodies(FrameCanvas& fc, const std::vector<Body>& bodies, bool want_image) {
  const auto& cd = fc.cd;
  const int w = cd.cam.width, h = cd.cam.height;
  const Vec3 o = cd.origin;
  BodyRaster r;
  if (!bodies.empty()) r.id.assign(static_cast<size_t>(w) * h, 0);
  r.boxes.resize(bodies.size());
  r.hits_all.assign(bodies.size(), 0);
  r.hit_bbox.resize(bodies.size());
  for (size_t k = 0; k < bodies.size(); ++k) {
    const Body& b = bodies[k];
    r.boxes[k] = ProjectBox(cd.cam, b.box_min, b.box_max);
    const cv::Rect& box = r.boxes[k];
    int bx0 = w, by0 = h, bx1 = -1, by1 = -1;
    if (box.empty()) continue;
    // Rasterise primitive by primitive inside its own box: nearest distance and primitive.
    std::vector<float> best_t(static_cast<size_t>(box.area()),
                              std::numeric_limits<float>::infinity());
    std::vector<int16_t> best_p(static_cast<size_t>(box.area()), -1);
    const int np = NumPrimitives(b);
    for (int q = 0; q < np; ++q) {
      Vec3 lo, hi;
      PrimitiveBounds(b, q, &lo, &hi);
      const cv::Rect pbox = ProjectBox(cd.cam, lo, hi) & box;
      for (int v = pbox.y; v < pbox.y + pbox.height; ++v) {
        for (int u = pbox.x; u < pbox.x + pbox.width; ++u) {
          const Vec3 d = fc.Ray(u, v);
          if (!d.allFinite()) continue;
          const double tq = IntersectPrimitive(b, q, o, d);
          const size_t j = static_cast<size_t>(v - box.y) * box.width + (u - box.x);
          if (tq > 1e-6 && tq < best_t[j]) {
            best_t[j] = static_cast<float>(tq);
            best_p[j] = static_cast<int16_t>(q);
          }
        }
      }
    }
    for (int v = box.y; v < box.y + box.height; ++v) {
      auto* row = fc.img.ptr<cv::Vec3b>(v);
      float* drow = fc.depth.ptr<float>(v);
      for (int u = box.x; u < box.x + box.width; ++u) {
        const size_t j = static_cast<size_t>(v - box.y) * box.width + (u - box.x);
        if (best_p[j] < 0) continue;
        ++r.hits_all[k];
        bx0 = std::min(bx0, u);
        by0 = std::min(by0, v);
        bx1 = std::max(bx1, u);
        by1 = std::max(by1, v);
        if (best_t[j] >= drow[u]) continue;
        drow[u] = best_t[j];
        r.id[static_cast<size_t>(v) * w + u] = static_cast<uint16_t>(k + 1);
        if (want_image) {
          const Hit hit = ShadePrimitive(b, best_p[j], o, fc.Ray(u, v), best_t[j]);
          const double shade = Lambert(fc.lighting, hit.normal.dot(fc.light), 0.5, 0.6);
          const Vec3 c = Clamp255(hit.colour * shade);
          row[u] = cv::Vec3b(static_cast<uint8_t>(c[0]), static_cast<uint8_t>(c[1]),
                             static_cast<uint8_t>(c[2]));
        }
      }
    }
    if (bx1 >= 0) r.hit_bbox[k] = cv::Rect(bx0, by0, bx1 - bx0 + 1, by1 - by0 + 1);
  }
  return r;
}

// Per person: in the image, its bounding box and unoccluded share.
std::vector<PlayerCameraTruth> PeopleTruth(const BodyRaster& r, size_t num_people, int w) {
  std::vector<PlayerCameraTruth> out(num_people);
  for (size_t k = 0; k < num_people; ++k) {
    PlayerCameraTruth& pt = out[k];
    if (r.hits_all[k] == 0) continue;
    long vis = 0;
    const cv::Rect& box = r.boxes[k];
    for (int v = box.y; v < box.y + box.height; ++v) {
      for (int u = box.x; u < box.x + box.width; ++u) {
        vis += r.id[static_cast<size_t>(v) * w + u] == k + 1;
      }
    }
    pt.in_image = true;
    pt.bb_left = r.hit_bbox[k].x;
    pt.bb_top = r.hit_bbox[k].y;
    pt.bb_width = r.hit_bbox[k].width;
    pt.bb_height = r.hit_bbox[k].height;
    pt.visible_fraction = static_cast<double>(vis) / r.hits_all[k];
  }
  return out;
}

// Coverage of one pixel's ray d by a ball of radius r at centre c: the distance from the centre
// to the ray minus the radius, over the pixel's size at that depth; the hit distance and normal.
double BallCoverage(const SceneRenderer::CameraData& cd, double r, const Vec3& c, const Vec3& d,
                    double* t_hit, Vec3* normal) {
  const Vec3 oc = c - cd.origin;
  const double tc = oc.dot(d);
  if (tc <= r) return 0.0;
  const Vec3 perp = oc - tc * d;
  const double dist = perp.norm();
  const double fp = tc * cd.pixel_angle;
  const double cov = std::clamp(0.5 - (dist - r) / fp, 0.0, 1.0);
  if (cov <= 0) return 0.0;
  const double th = dist < r ? tc - std::sqrt(r * r - dist * dist) : tc;
  *t_hit = th;
  if (normal) *normal = (cd.origin + th * d - c).normalized();
  return cov;
}

// The ball's projection and the visible share of its disc at mid-exposure.
BallCameraTruth BallVisibility(const FrameCanvas& fc, const Vec3& ball_mid, double r_ball) {
  const auto& cd = fc.cd;
  const camera::Camera& cam = cd.cam;
  BallCameraTruth bt;
  Eigen::Vector2d uv_mid;
  double rad_mid = 0;
  bt.in_front = (cam.cam_from_world * ball_mid).z() > 0;
  if (ProjectSphere(cam, ball_mid, r_ball, &uv_mid, &rad_mid)) {
    bt.uv_px = uv_mid;
    bt.radius_px = rad_mid;
  } else if (const auto p = cam.Project(ball_mid)) {
    bt.uv_px = *p;
  }
  if (!bt.in_front || rad_mid <= 0) return bt;
  const double m = rad_mid * 1.3 + 2;
  const cv::Rect full(
      static_cast<int>(std::floor(uv_mid.x() - m)), static_cast<int>(std::floor(uv_mid.y() - m)),
      static_cast<int>(std::ceil(2 * m)) + 2, static_cast<int>(std::ceil(2 * m)) + 2);
  const cv::Rect box = full & cv::Rect(0, 0, cam.width, cam.height);
  double cov_all = 0, cov_vis = 0;
  for (int v = box.y; v < box.y + box.height; ++v) {
    const float* drow = fc.depth.ptr<float>(v);
    for (int u = box.x; u < box.x + box.width; ++u) {
      const Vec3 d = fc.Ray(u, v);
      if (!d.allFinite()) continue;
      double th;
      const double cov = BallCoverage(cd, r_ball, ball_mid, d, &th, nullptr);
      if (cov <= 0) continue;
      cov_all += cov;
      if (th < drow[u]) cov_vis += cov;
    }
  }
  const bool inside = box == full;
  const double denom = inside ? cov_all : M_PI * rad_mid * rad_mid;
  bt.visible_fraction = denom > 0 ? std::clamp(cov_vis / denom, 0.0, 1.0) : 0.0;
  return bt;
}

// The ball's colour at a point with normal n seen along d: albedo (with the print) shaded, plus
// the highlight.
Vec3 BallColour(const BallSpec& ball, const FrameCanvas& fc, const Eigen::Matrix3d& orientation,
                const Vec3& n, const Vec3& d, double px) {
  const Vec3& light = fc.light;
  const double ndl = n.dot(light);
  const Vec3 refl = 2 * ndl * n - light;
  const bool new_model = fc.lighting.ambient >= 0;
  const double spec =
      new_model && ndl <= 0 ? 0.0 : std::pow(std::max(0.0, -refl.dot(d)), ball.shininess);
  Vec3 albedo = ball.colour_bgr;
  if (ball.pattern != "none") {
    const double m = PatternCover(ball.pattern, orientation.transpose() * n, px);
    albedo = (1 - m) * albedo + m * ball.pattern_bgr;
  }
  return albedo * Lambert(fc.lighting, ndl, 0.5, 0.6) + Vec3::Constant(ball.specular * spec);
}

// The ball anti-aliased, shaded and averaged over the sub-exposure samples (motion blur).
void DrawBall(FrameCanvas& fc, const BallSpec& ball, const std::vector<BallSample>& samples) {
  const auto& cd = fc.cd;
  const camera::Camera& cam = cd.cam;
  const double r_ball = ball.radius_m();
  cv::Rect box;
  std::vector<BallSample> seen;
  for (const BallSample& s : samples) {
    Eigen::Vector2d uv;
    double rad;
    if (!ProjectSphere(cam, s.centre, r_ball, &uv, &rad)) continue;
    seen.push_back(s);
    const double m = rad * 1.3 + 2;
    const cv::Rect b(
        static_cast<int>(std::floor(uv.x() - m)), static_cast<int>(std::floor(uv.y() - m)),
        static_cast<int>(std::ceil(2 * m)) + 2, static_cast<int>(std::ceil(2 * m)) + 2);
    box = box.empty() ? b : (box | b);
  }
  box &= cv::Rect(0, 0, cam.width, cam.height);
  const double inv_k = 1.0 / static_cast<double>(samples.size());
  for (int v = box.y; v < box.y + box.height; ++v) {
    auto* row = fc.img.ptr<cv::Vec3b>(v);
    const float* drow = fc.depth.ptr<float>(v);
    for (int u = box.x; u < box.x + box.width; ++u) {
      const Vec3 d = fc.Ray(u, v);
      if (!d.allFinite()) continue;
      const Vec3 pix(row[u][0], row[u][1], row[u][2]);
      Vec3 acc = Vec3::Zero();
      for (const BallSample& s : seen) {
        double th;
        Vec3 n = Vec3::UnitZ();
        const double cov = BallCoverage(cd, r_ball, s.centre, d, &th, &n);
        if (cov <= 0 || th >= drow[u]) continue;
        const double px = th * cd.pixel_angle / r_ball;
        acc += cov * (Clamp255(BallColour(ball, fc, s.orientation, n, d, px)) - pix);
      }
      if (acc.isZero()) continue;
      const Vec3 c = Clamp255(pix + inv_k * acc);
      row[u] = cv::Vec3b(static_cast<uint8_t>(std::lround(c[0])),
                         static_cast<uint8_t>(std::lround(c[1])),
                         static_cast<uint8_t>(std::lround(c[2])));
    }
  }
}

// Exposure gain, white balance, vignetting and sensor noise (fresh per frame, seeded by scene,
// camera and frame).
void ApplyCameraResponse(cv::Mat& img, const SceneRenderer::CameraData& cd, const SceneSpec& spec,
                         const std::vector<int16_t>& noise_table, int camera, int frame, double t) {
  const int w = cd.cam.width, h = cd.cam.height;
  const LightingSpec& l = spec.lighting;
  const double gain = 1.0 + l.gain_amplitude * std::sin(2 * M_PI * t / l.period_s);
  const double wb = l.white_balance_amplitude * std::sin(2 * M_PI * t / l.white_balance_period_s);
  const float wbf[3] = {static_cast<float>(1 + wb), 1.0f, static_cast<float>(1 - wb)};
  const bool noise = spec.noise_sigma > 0;
  for (int v = 0; v < h; ++v) {
    uint8_t* row = img.ptr<uint8_t>(v);
    const float* vig = cd.vignette.data() + static_cast<size_t>(v) * w;
    uint64_t state = spec.seed * 0x9E3779B97F4A7C15ULL ^ (static_cast<uint64_t>(camera) << 48) ^
                     (static_cast<uint64_t>(frame) << 20) ^ static_cast<uint64_t>(v);
    uint64_t bits = 0;
    int left = 0;
    for (int u = 0; u < w; ++u) {
      const float f = static_cast<float>(gain) * vig[u];
      for (int ch = 0; ch < 3; ++ch) {
        float val = row[3 * u + ch] * (f * wbf[ch]);
        if (noise) {
          if (left == 0) {
            bits = SplitMix(state);
            left = 4;
          }
          val += noise_table[bits & 0xffff];
          bits >>= 16;
          --left;
        }
        row[3 * u + ch] = static_cast<uint8_t>(std::clamp(val + 0.5f, 0.0f, 255.0f));
      }
    }
  }
}

}  // namespace

cv::Mat SceneRenderer::RenderInternal(int camera, int frame, CameraFrameStats* stats,
                                      bool want_image) const {
  FV_REQUIRE(camera >= 0 && camera < static_cast<int>(data_.size()),
             "camera index {} out of range (0..{})", camera, data_.size() - 1);
  FV_REQUIRE(frame >= 0, "frame {} must be >= 0", frame);
  const CameraData& cd = *data_[camera];
  const double t = FrameTime(frame);
  FrameCanvas fc{cd, spec_.lighting, spec_.lighting.Direction(), cd.bg.clone(), cd.depth.clone()};

  // Bodies: people, then robots.
  std::vector<Body> bodies;
  for (const auto& p : spec_.people) bodies.push_back(PersonBody(p, spec_.teams[p.team], t));
  for (size_t i = 0; i < spec_.robots.size(); ++i) {
    bodies.push_back(RobotBody(spec_.robots[i], static_cast<int>(i), t, spec_.ball.radius_m()));
  }
  const bool has_ball = spec_.ball.enabled;
  const double r_ball = spec_.ball.radius_m();
  const Vec3 ball_mid = has_ball ? BallAt(t) : Vec3::Zero();

  if (want_image && spec_.lighting.shadows) CastShadows(fc, bodies, has_ball, ball_mid, r_ball);
  const BodyRaster raster = DrawBodies(fc, bodies, want_image);
  if (stats) stats->players = PeopleTruth(raster, spec_.people.size(), cd.cam.width);
  if (has_ball) {
    if (stats) stats->ball = BallVisibility(fc, ball_mid, r_ball);
    if (want_image) DrawBall(fc, spec_.ball, BallSamples(camera, t));
  }
  if (!want_image) return {};
  ApplyCameraResponse(fc.img, cd, spec_, noise_table_, camera, frame, t);
  return fc.img;
}

std::vector<cv::Mat> SceneRenderer::Render(int frame) const {
  std::vector<cv::Mat> out(cameras_.size());
  util::ParallelFor(cameras_.size(),
                    [&](size_t i) { out[i] = RenderCamera(static_cast<int>(i), frame); });
  return out;
}

BallTruthFrame SceneRenderer::BallTruth(int frame) const {
  BallTruthFrame b;
  b.frame = frame;
  b.time_s = FrameTime(frame);
  b.present = spec_.ball.enabled;
  if (!b.present) return b;
  b.centre_m = BallAt(b.time_s);
  for (size_t i = 0; i < cameras_.size(); ++i) {
    b.cameras.push_back(CameraTruth(static_cast<int>(i), frame).ball);
    if (b.cameras.back().in_front && b.cameras.back().visible_fraction >= 0.3) ++b.n_cams;
  }
  return b;
}

std::vector<PersonTruth> SceneRenderer::PlayerTruth(int frame) const {
  const double t = FrameTime(frame);
  std::vector<PersonTruth> out;
  for (const auto& p : spec_.people) {
    PersonTruth pt;
    pt.id = p.id;
    pt.team = p.team;
    const PathState s = PathAt(p.path, t);
    pt.x_m = s.position_m.x();
    pt.y_m = s.position_m.y();
    out.push_back(pt);
  }
  if (out.empty()) return out;
  for (size_t i = 0; i < cameras_.size(); ++i) {
    const CameraFrameStats s = CameraTruth(static_cast<int>(i), frame);
    for (size_t k = 0; k < out.size(); ++k) out[k].cameras.push_back(s.players[k]);
  }
  return out;
}

}  // namespace fv::synth
