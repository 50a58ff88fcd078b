// SceneSpec: validation, JSON round trip and the presets.
#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "fieldvision/geometry/rigid.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/random.h"

namespace fv::synth {
namespace {

using nlohmann::json;

json PathToJson(const PathSpec& p) {
  json j;
  j["waypoints_m"] = json::array();
  for (const auto& w : p.waypoints_m) j["waypoints_m"].push_back(util::JsonFromVector(w));
  j["speed_mps"] = p.speed_mps;
  if (!p.speeds_mps.empty()) j["speeds_mps"] = p.speeds_mps;
  j["start_s"] = p.start_s;
  return j;
}

PathSpec PathFromJson(const json& o, const std::string& ctx) {
  util::JsonKnownKeys(o, ctx, {"waypoints_m", "speed_mps", "speeds_mps", "start_s"});
  PathSpec p;
  const json& w = util::JsonArray(o, "waypoints_m", ctx);
  for (size_t i = 0; i < w.size(); ++i) {
    p.waypoints_m.push_back(util::JsonVectorOf<2>(w[i], fmt::format("{}.waypoints_m[{}]", ctx, i)));
  }
  p.speed_mps = util::JsonNumber(o, "speed_mps", ctx, p.speed_mps);
  p.speeds_mps = util::JsonNumbers(o, "speeds_mps", ctx, false);
  p.start_s = util::JsonNumber(o, "start_s", ctx, p.start_s);
  return p;
}

// ---- SceneSpecFromJson's parts, each naming its key path in errors.

CameraSpec CameraSpecFromJson(const json& c, size_t i) {
  const std::string ctx = fmt::format("cameras[{}]", i);
  util::JsonKnownKeys(c, ctx,
                      {"name", "width", "height", "hfov_deg", "fx", "fy", "distortion",
                       "position_m", "look_at_m", "rvec", "tvec"});
  CameraSpec cs;
  cs.name = util::JsonString(c, "name", ctx, fmt::format("cam{}", i + 1));
  cs.width = util::JsonInt(c, "width", ctx, cs.width);
  cs.height = util::JsonInt(c, "height", ctx, cs.height);
  cs.hfov_deg = util::JsonNumber(c, "hfov_deg", ctx, cs.hfov_deg);
  cs.fx = util::JsonNumber(c, "fx", ctx, 0.0);
  cs.fy = util::JsonNumber(c, "fy", ctx, cs.fx);
  cs.distortion = util::JsonNumbers(c, "distortion", ctx, false);
  if (util::JsonHas(c, "rvec") || util::JsonHas(c, "tvec")) {
    FV_REQUIRE(util::JsonHas(c, "rvec") && util::JsonHas(c, "tvec"), "{}: give both rvec and tvec",
               ctx);
    cs.has_rvec_tvec = true;
    cs.rvec = util::JsonVector<3>(c, "rvec", ctx, cs.rvec);
    cs.tvec = util::JsonVector<3>(c, "tvec", ctx, cs.tvec);
  } else {
    FV_REQUIRE(util::JsonHas(c, "position_m"), "{}.position_m: missing (or give rvec and tvec)",
               ctx);
    FV_REQUIRE(util::JsonHas(c, "look_at_m"), "{}.look_at_m: missing (or give rvec and tvec)", ctx);
    cs.position_m = util::JsonVector<3>(c, "position_m", ctx, cs.position_m);
    cs.look_at_m = util::JsonVector<3>(c, "look_at_m", ctx, cs.look_at_m);
  }
  return cs;
}

BallSpec BallSpecFromJson(const json& b, BallSpec ball) {
  util::JsonKnownKeys(
      b, "ball",
      {"enabled", "diameter_m", "colour_bgr", "placements", "hold_frames", "kicks", "held_by",
       "physics", "specular", "shininess", "pattern", "pattern_bgr", "orientation_rvec"});
  ball.enabled = util::JsonBool(b, "enabled", "ball", true);
  ball.diameter_m = util::JsonNumber(b, "diameter_m", "ball", ball.diameter_m);
  ball.colour_bgr = util::JsonVector<3>(b, "colour_bgr", "ball", ball.colour_bgr);
  const json& pl = util::JsonArray(b, "placements", "ball");
  for (size_t i = 0; i < pl.size(); ++i) {
    ball.placements.push_back(util::JsonVectorOf<3>(pl[i], fmt::format("ball.placements[{}]", i)));
  }
  ball.hold_frames = util::JsonInt(b, "hold_frames", "ball", ball.hold_frames);
  const json& ks = util::JsonArray(b, "kicks", "ball");
  for (size_t i = 0; i < ks.size(); ++i) {
    const std::string ctx = fmt::format("ball.kicks[{}]", i);
    util::JsonKnownKeys(ks[i], ctx, {"time_s", "position_m", "velocity_mps", "spin_radps"});
    KickSpec k;
    k.time_s = util::JsonNumber(ks[i], "time_s", ctx, 0.0);
    FV_REQUIRE(util::JsonHas(ks[i], "position_m"), "{}.position_m: missing", ctx);
    k.position_m = util::JsonVector<3>(ks[i], "position_m", ctx, k.position_m);
    FV_REQUIRE(util::JsonHas(ks[i], "velocity_mps"), "{}.velocity_mps: missing", ctx);
    k.velocity_mps = util::JsonVector<3>(ks[i], "velocity_mps", ctx, k.velocity_mps);
    k.spin_radps = util::JsonVector<3>(ks[i], "spin_radps", ctx, k.spin_radps);
    ball.kicks.push_back(k);
  }
  ball.held_by = util::JsonInt(b, "held_by", "ball", ball.held_by);
  ball.specular = util::JsonNumber(b, "specular", "ball", ball.specular);
  ball.shininess = util::JsonNumber(b, "shininess", "ball", ball.shininess);
  ball.pattern = util::JsonString(b, "pattern", "ball", ball.pattern);
  ball.pattern_bgr = util::JsonVector<3>(b, "pattern_bgr", "ball", ball.pattern_bgr);
  ball.orientation_rvec = util::JsonVector<3>(b, "orientation_rvec", "ball", ball.orientation_rvec);
  const json& ph = util::JsonObject(b, "physics", "ball");
  const std::string pc = "ball.physics";
  util::JsonKnownKeys(
      ph, pc,
      {"gravity_mps2", "drag_coefficient", "air_density_kgm3", "mass_kg", "restitution",
       "bounce_friction", "rolling_resistance", "min_bounce_speed_mps", "time_step_s"});
  BallPhysics& p = ball.physics;
  p.gravity_mps2 = util::JsonNumber(ph, "gravity_mps2", pc, p.gravity_mps2);
  p.drag_coefficient = util::JsonNumber(ph, "drag_coefficient", pc, p.drag_coefficient);
  p.air_density_kgm3 = util::JsonNumber(ph, "air_density_kgm3", pc, p.air_density_kgm3);
  p.mass_kg = util::JsonNumber(ph, "mass_kg", pc, p.mass_kg);
  p.restitution = util::JsonNumber(ph, "restitution", pc, p.restitution);
  p.bounce_friction = util::JsonNumber(ph, "bounce_friction", pc, p.bounce_friction);
  p.rolling_resistance = util::JsonNumber(ph, "rolling_resistance", pc, p.rolling_resistance);
  p.min_bounce_speed_mps = util::JsonNumber(ph, "min_bounce_speed_mps", pc, p.min_bounce_speed_mps);
  p.time_step_s = util::JsonNumber(ph, "time_step_s", pc, p.time_step_s);
  return ball;
}

RobotSpec RobotSpecFromJson(const json& robot, size_t i) {
  const std::string ctx = fmt::format("robots[{}]", i);
  util::JsonKnownKeys(
      robot, ctx,
      {"path", "position_m", "radius_m", "height_m", "colour_bgr", "handler", "heading_deg"});
  RobotSpec r;
  if (util::JsonHas(robot, "path")) r.path = PathFromJson(robot["path"], ctx + ".path");
  if (util::JsonHas(robot, "position_m")) {
    r.path.waypoints_m.insert(
        r.path.waypoints_m.begin(),
        util::JsonVector<2>(robot, "position_m", ctx, Eigen::Vector2d::Zero()));
  }
  r.radius_m = util::JsonNumber(robot, "radius_m", ctx, r.radius_m);
  r.height_m = util::JsonNumber(robot, "height_m", ctx, r.height_m);
  r.colour_bgr = util::JsonVector<3>(robot, "colour_bgr", ctx, r.colour_bgr);
  r.handler = util::JsonBool(robot, "handler", ctx, r.handler);
  r.heading_deg = util::JsonNumber(robot, "heading_deg", ctx, r.heading_deg);
  return r;
}

PersonSpec PersonSpecFromJson(const json& person, size_t i) {
  const std::string ctx = fmt::format("people[{}]", i);
  util::JsonKnownKeys(person, ctx, {"id", "team", "path", "height_m", "skin_bgr"});
  PersonSpec p;
  p.id = util::JsonInt(person, "id", ctx, static_cast<int>(i) + 1);
  p.team = util::JsonInt(person, "team", ctx, 0);
  FV_REQUIRE(util::JsonHas(person, "path"), "{}.path: missing", ctx);
  p.path = PathFromJson(person["path"], ctx + ".path");
  p.height_m = util::JsonNumber(person, "height_m", ctx, p.height_m);
  p.skin_bgr = util::JsonVector<3>(person, "skin_bgr", ctx, p.skin_bgr);
  return p;
}

TeamSpec TeamSpecFromJson(const json& team, size_t i) {
  const std::string ctx = fmt::format("teams[{}]", i);
  util::JsonKnownKeys(team, ctx, {"name", "shirt_bgr", "shorts_bgr"});
  TeamSpec t;
  t.name = util::JsonString(team, "name", ctx, fmt::format("team{}", i));
  t.shirt_bgr = util::JsonVector<3>(team, "shirt_bgr", ctx, t.shirt_bgr);
  t.shorts_bgr = util::JsonVector<3>(team, "shorts_bgr", ctx, t.shorts_bgr);
  return t;
}

ConeSpec ConeSpecFromJson(const json& cone, size_t i) {
  const std::string ctx = fmt::format("cones[{}]", i);
  util::JsonKnownKeys(cone, ctx, {"position_m", "height_m", "base_radius_m", "colour_bgr"});
  ConeSpec c;
  FV_REQUIRE(util::JsonHas(cone, "position_m"), "{}.position_m: missing", ctx);
  c.position_m = util::JsonVector<2>(cone, "position_m", ctx, c.position_m);
  c.height_m = util::JsonNumber(cone, "height_m", ctx, c.height_m);
  c.base_radius_m = util::JsonNumber(cone, "base_radius_m", ctx, c.base_radius_m);
  c.colour_bgr = util::JsonVector<3>(cone, "colour_bgr", ctx, c.colour_bgr);
  return c;
}

LightingSpec LightingSpecFromJson(const json& l, LightingSpec lighting) {
  util::JsonKnownKeys(
      l, "lighting",
      {"light_dir", "sun_elevation_deg", "sun_azimuth_deg", "ambient", "gain_amplitude", "period_s",
       "white_balance_amplitude", "white_balance_period_s", "vignetting", "shadows"});
  const std::string lc = "lighting";
  lighting.light_dir = util::JsonVector<3>(l, "light_dir", lc, lighting.light_dir);
  lighting.sun_elevation_deg =
      util::JsonNumber(l, "sun_elevation_deg", lc, lighting.sun_elevation_deg);
  lighting.sun_azimuth_deg = util::JsonNumber(l, "sun_azimuth_deg", lc, lighting.sun_azimuth_deg);
  lighting.ambient = util::JsonNumber(l, "ambient", lc, lighting.ambient);
  lighting.white_balance_amplitude =
      util::JsonNumber(l, "white_balance_amplitude", lc, lighting.white_balance_amplitude);
  lighting.white_balance_period_s =
      util::JsonNumber(l, "white_balance_period_s", lc, lighting.white_balance_period_s);
  lighting.gain_amplitude =
      util::JsonNumber(l, "gain_amplitude", "lighting", lighting.gain_amplitude);
  lighting.period_s = util::JsonNumber(l, "period_s", "lighting", lighting.period_s);
  lighting.vignetting = util::JsonNumber(l, "vignetting", "lighting", lighting.vignetting);
  lighting.shadows = util::JsonBool(l, "shadows", "lighting", lighting.shadows);
  return lighting;
}

void CheckPath(const PathSpec& p, const std::string& ctx) {
  FV_REQUIRE(!p.waypoints_m.empty(), "{}.waypoints_m: needs at least one point", ctx);
  for (size_t i = 0; i < p.waypoints_m.size(); ++i) {
    FV_REQUIRE(p.waypoints_m[i].allFinite(), "{}.waypoints_m[{}]: not finite", ctx, i);
  }
  FV_REQUIRE(std::isfinite(p.speed_mps) && p.speed_mps > 0, "{}.speed_mps: must be > 0", ctx);
  FV_REQUIRE(p.speeds_mps.empty() || p.speeds_mps.size() + 1 == p.waypoints_m.size(),
             "{}.speeds_mps: needs one speed per leg ({}), has {}", ctx, p.waypoints_m.size() - 1,
             p.speeds_mps.size());
  for (size_t i = 0; i < p.speeds_mps.size(); ++i) {
    FV_REQUIRE(std::isfinite(p.speeds_mps[i]) && p.speeds_mps[i] > 0,
               "{}.speeds_mps[{}]: must be > 0", ctx, i);
  }
  FV_REQUIRE(std::isfinite(p.start_s), "{}.start_s: not finite", ctx);
}

void CheckColour(const Eigen::Vector3d& c, const std::string& ctx) {
  for (int i = 0; i < 3; ++i) {
    FV_REQUIRE(std::isfinite(c[i]) && c[i] >= 0 && c[i] <= 255,
               "{}: colour values must be in 0..255 (BGR)", ctx);
  }
}

// A rig of 4 cameras at the corners of a field, outside the playing area, looking at it.
std::vector<CameraSpec> CornerRig(const field::FieldModel& f, double height_m, int w, int h,
                                  double hfov_deg) {
  std::vector<CameraSpec> cams;
  const double hx = 0.5 * f.length_m + 0.9 * f.surround_m;
  const double hy = 0.5 * f.width_m + 0.9 * f.surround_m;
  const int sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (int i = 0; i < 4; ++i) {
    CameraSpec c;
    c.name = fmt::format("cam{}", i + 1);
    c.width = w;
    c.height = h;
    c.hfov_deg = hfov_deg;
    c.distortion = {-0.06, 0.02, 0.0, 0.0, 0.0};
    c.position_m = Eigen::Vector3d(sx[i] * hx, sy[i] * hy, height_m);
    // Look at a point a little towards the camera from the centre so the near corner is in view.
    c.look_at_m = Eigen::Vector3d(sx[i] * 0.06 * f.length_m, sy[i] * 0.06 * f.width_m, 0.0);
    cams.push_back(c);
  }
  return cams;
}

// Random draws in the presets are one per statement: the arguments of one call are evaluated in
// an unspecified order (GCC right to left, clang left to right), so a call with two draws gave
// each compiler another scene for the same seed. They are sequenced in GCC's order, which keeps
// the scenes written so far.

// The presets' start: the MSL field seen by the 4-camera corner rig (1280x960, 75 deg, 4 m up).
SceneSpec MslCornerScene(uint64_t seed, double fps, int num_frames) {
  SceneSpec s;
  s.seed = seed;
  s.field = "robocup-msl";
  s.cameras = CornerRig(field::BuiltinField(s.field), 4.0, 1280, 960, 75.0);
  s.fps = fps;
  s.num_frames = num_frames;
  return s;
}

SceneSpec StaticPreset(uint64_t seed) {
  SceneSpec s = MslCornerScene(seed, 30, 16);
  const field::FieldModel f = field::BuiltinField(s.field);
  util::Rng rng(seed * 7919 + 17);
  const double r = s.ball.radius_m();
  for (int i = 0; i < s.num_frames; ++i) {
    const double y = rng.Uniform(-0.42, 0.42) * f.width_m;  // sequenced: see MslCornerScene
    const double x = rng.Uniform(-0.42, 0.42) * f.length_m;
    Eigen::Vector3d p(x, y, r);
    if (i % 3 != 0) p.z() = rng.Uniform(r, 3.0);
    s.ball.placements.push_back(p);
  }
  s.noise_sigma = 1.5;
  return s;
}

SceneSpec KickPreset(uint64_t seed) {
  SceneSpec s = MslCornerScene(seed, 60, 192);
  util::Rng rng(seed * 104729 + 3);
  const double r = s.ball.radius_m();
  KickSpec k;
  k.time_s = 0.25;
  k.position_m.y() = -2.0 + rng.Uniform(-0.5, 0.5);  // sequenced: see MslCornerScene
  k.position_m.x() = -5.5 + rng.Uniform(-0.5, 0.5);
  k.position_m.z() = r;
  k.velocity_mps.z() = 7.0 + rng.Uniform(-0.4, 0.4);
  k.velocity_mps.y() = 2.0 + rng.Uniform(-0.5, 0.5);
  k.velocity_mps.x() = 5.5 + rng.Uniform(-0.5, 0.5);
  s.ball.kicks.push_back(k);
  s.exposure_s = 1.0 / 250.0;
  // A robot just in front of the ball's start as seen from cam1 (hides it before the kick), one
  // near the first landing and one moving across the field.
  const Eigen::Vector3d cam1 = s.cameras[0].position_m;
  const Eigen::Vector2d to_cam = (cam1.head<2>() - k.position_m.head<2>()).normalized();
  RobotSpec r1;
  r1.path.waypoints_m = {k.position_m.head<2>() + 0.6 * to_cam};
  RobotSpec r2;
  r2.path.waypoints_m = {Eigen::Vector2d(2.5, 1.0), Eigen::Vector2d(3.5, -2.0)};
  r2.path.speed_mps = 1.0;
  RobotSpec r3;
  r3.path.waypoints_m = {Eigen::Vector2d(-1.0, 4.0), Eigen::Vector2d(-3.0, 0.5)};
  r3.path.speed_mps = 1.5;
  r3.colour_bgr = Eigen::Vector3d(25, 25, 30);
  s.robots = {r1, r2, r3};
  ConeSpec cone;
  cone.position_m.y() = -3.5 + rng.Uniform(-0.5, 0.5);  // sequenced: see MslCornerScene
  cone.position_m.x() = 1.0 + rng.Uniform(-1, 1);
  s.cones = {cone};
  s.lighting.gain_amplitude = 0.08;
  s.lighting.period_s = 6.0;
  return s;
}

SceneSpec PlayersPreset(uint64_t seed) {
  SceneSpec s;
  s.seed = seed;
  s.field = "robocup-msl";
  const field::FieldModel f = field::BuiltinField(s.field);
  CameraSpec c;
  c.name = "side";
  c.width = 1280;
  c.height = 960;
  c.hfov_deg = 88;
  c.distortion = {-0.08, 0.015, 0.0, 0.0, 0.0};
  c.position_m = Eigen::Vector3d(0.0, -0.5 * f.width_m - 0.8 * f.surround_m, 6.0);
  c.look_at_m = Eigen::Vector3d(0.0, 0.5, 0.0);
  s.cameras = {c};
  s.fps = 25;
  s.num_frames = 250;
  s.ball.enabled = false;
  util::Rng rng(seed * 15485863 + 11);
  const double hx = 0.45 * f.length_m, hy = 0.42 * f.width_m;
  for (int i = 0; i < 8; ++i) {
    PersonSpec p;
    p.id = i + 1;
    p.team = i % 2;
    p.height_m = rng.Uniform(1.68, 1.92);
    const double tone = rng.Uniform(0.55, 1.0);
    p.skin_bgr = Eigen::Vector3d(110 + 60 * tone, 140 + 50 * tone, 175 + 60 * tone);
    // Paths cross the field: each starts on one side and goes to the other, with random turns.
    const double side = (i % 2 == 0) ? -1.0 : 1.0;
    const double y0 = rng.Uniform(-hy, hy);  // sequenced: see MslCornerScene
    p.path.waypoints_m.push_back(Eigen::Vector2d(side * rng.Uniform(0.3, 1.0) * hx, y0));
    const int n = 3 + rng.UniformInt(0, 2);
    for (int k = 0; k < n; ++k) {
      const double x = (k % 2 == 0 ? -side : side) * rng.Uniform(0.2, 1.0) * hx;
      p.path.waypoints_m.push_back(Eigen::Vector2d(x, rng.Uniform(-hy, hy)));
    }
    for (int k = 0; k < n; ++k) {
      p.path.speeds_mps.push_back(rng.Uniform() < 0.5 ? rng.Uniform(1.2, 1.7)
                                                      : rng.Uniform(4.0, 6.0));
    }
    p.path.speed_mps = p.path.speeds_mps[0];
    s.people.push_back(p);
  }
  s.lighting.gain_amplitude = 0.05;
  s.lighting.period_s = 8;
  s.noise_sigma = 2.0;
  s.format = "avi";
  return s;
}

// Low sun and a printed yellow ball (RoboCup MSL style): the side away from the sun at 35 % of
// the lit side, a strong highlight, exposure and white balance drifting.
void ApplyLowSun(SceneSpec& s) {
  s.lighting.sun_elevation_deg = 30.0;
  s.lighting.sun_azimuth_deg = 35.0;
  s.lighting.ambient = 0.35;
  s.lighting.gain_amplitude = 0.06;
  s.lighting.period_s = 5.0;
  s.lighting.white_balance_amplitude = 0.04;
  s.lighting.white_balance_period_s = 7.0;
  s.ball.colour_bgr = Eigen::Vector3d(20, 215, 245);
  s.ball.pattern = "print";
  s.ball.pattern_bgr = Eigen::Vector3d(60, 35, 30);
  s.ball.specular = 110.0;
  s.ball.shininess = 40.0;
}

SceneSpec LowSunKickPreset(uint64_t seed) {
  SceneSpec s = KickPreset(seed);
  ApplyLowSun(s);
  // Backspin of 8 turns per second about the horizontal axis across the flight.
  for (KickSpec& k : s.ball.kicks) {
    const Eigen::Vector3d v(k.velocity_mps.x(), k.velocity_mps.y(), 0.0);
    if (v.norm() > 1e-9) {
      k.spin_radps = 2 * M_PI * 8.0 * v.normalized().cross(Eigen::Vector3d::UnitZ());
    }
  }
  return s;
}

// Four corner cameras with equidistant-like fisheye lenses (130 deg across the width); the balls
// are placed where cam1 sees them near its image border (within 12 % of the width of it).
SceneSpec FisheyePreset(uint64_t seed) {
  SceneSpec s = StaticPreset(seed);
  const field::FieldModel f = field::BuiltinField(s.field);
  for (CameraSpec& c : s.cameras) {
    c.fx = c.fy = FisheyeFocalPx(c.width, 130.0);
    c.distortion = FisheyeDistortion();
  }
  camera::Camera cam1;
  cam1.width = s.cameras[0].width;
  cam1.height = s.cameras[0].height;
  cam1.fx = cam1.fy = s.cameras[0].fx;
  cam1.cx = 0.5 * (cam1.width - 1);
  cam1.cy = 0.5 * (cam1.height - 1);
  cam1.distortion = s.cameras[0].distortion;
  cam1.has_pose = true;
  cam1.cam_from_world = geometry::Rigid3d::LookAt(s.cameras[0].position_m, s.cameras[0].look_at_m);
  util::Rng rng(seed * 2654435761ULL + 5);
  const double r = s.ball.radius_m();
  const double margin = 0.12 * cam1.width;
  s.ball.placements.clear();
  for (int tries = 0; tries < 200000 && static_cast<int>(s.ball.placements.size()) < s.num_frames;
       ++tries) {
    // Sequenced: see MslCornerScene.
    const double z = rng.Uniform() < 0.5 ? r : rng.Uniform(r, 2.0);
    const double y = rng.Uniform(-0.5, 0.5) * f.width_m;
    const Eigen::Vector3d p(rng.Uniform(-0.5, 0.5) * f.length_m, y, z);
    const auto uv = cam1.Project(p);
    if (!uv) continue;
    const double border =
        std::min({uv->x(), uv->y(), cam1.width - 1 - uv->x(), cam1.height - 1 - uv->y()});
    const double radius_px = r / cam1.PixelFootprintM(p);
    if (border < radius_px + 2 || border > margin) continue;
    s.ball.placements.push_back(p);
  }
  FV_REQUIRE(static_cast<int>(s.ball.placements.size()) == s.num_frames,
             "fisheye preset: found only {} ball placements near cam1's border",
             s.ball.placements.size());
  return s;
}

// Four corner cameras and a robot with a handler holding the ball, driving back and forth (the
// handler towards a seeded heading), a second robot standing near it.
SceneSpec HeldPreset(uint64_t seed) {
  SceneSpec s = StaticPreset(seed);
  s.ball.placements.clear();
  s.num_frames = 24;
  s.fps = 30;
  util::Rng rng(seed * 40503 + 9);
  RobotSpec r1;
  r1.handler = true;
  r1.heading_deg = rng.Uniform(0.0, 360.0);
  const double y1 = rng.Uniform(-3, 3);  // sequenced: see MslCornerScene
  r1.path.waypoints_m = {Eigen::Vector2d(rng.Uniform(-4, 4), y1)};
  r1.path.waypoints_m.push_back(r1.path.waypoints_m[0] + Eigen::Vector2d(1.5, 1.0));
  r1.path.speed_mps = 1.0;
  RobotSpec r2;
  r2.path.waypoints_m = {r1.path.waypoints_m[0] + Eigen::Vector2d(-1.2, 0.8)};
  r2.colour_bgr = Eigen::Vector3d(25, 25, 30);
  s.robots = {r1, r2};
  s.ball.held_by = 0;
  s.ball.hold_frames = 1;
  return s;
}

// ---- SceneSpec::Check's parts.

// A camera's size, focal length, distortion and pose (its name is checked with the others').
void CheckCameraSpec(const CameraSpec& c, const std::string& ctx) {
  FV_REQUIRE(c.width > 0 && c.width <= 16384, "{}.width: must be in 1..16384", ctx);
  FV_REQUIRE(c.height > 0 && c.height <= 16384, "{}.height: must be in 1..16384", ctx);
  if (c.fx > 0 || c.fy > 0) {
    FV_REQUIRE(std::isfinite(c.fx) && c.fx > 0, "{}.fx: must be > 0", ctx);
    FV_REQUIRE(std::isfinite(c.fy) && c.fy > 0, "{}.fy: must be > 0", ctx);
  } else {
    FV_REQUIRE(std::isfinite(c.hfov_deg) && c.hfov_deg > 1 && c.hfov_deg < 179,
               "{}.hfov_deg: must be in (1, 179)", ctx);
  }
  const size_t nd = c.distortion.size();
  FV_REQUIRE(nd == 0 || nd == 4 || nd == 5 || nd == 8 || nd == 12 || nd == 14,
             "{}.distortion: has {} values; OpenCV takes 0, 4, 5, 8, 12 or 14", ctx, nd);
  for (double d : c.distortion) {
    FV_REQUIRE(std::isfinite(d), "{}.distortion: contains a non-finite value", ctx);
  }
  if (c.has_rvec_tvec) {
    FV_REQUIRE(c.rvec.allFinite() && c.tvec.allFinite(), "{}.rvec/tvec: not finite", ctx);
    // The ground is opaque: a camera under it sees nothing (a flipped z, z down, is the usual
    // cause).
    const double z = geometry::Rigid3d::FromRvecTvec(c.rvec, c.tvec).Inverse().translation.z();
    FV_REQUIRE(z >= 0, "{}.rvec/tvec: the camera is {:.3g} m below the ground (z points up)", ctx,
               -z);
  } else {
    FV_REQUIRE(c.position_m.allFinite(), "{}.position_m: not finite", ctx);
    FV_REQUIRE(c.position_m.z() >= 0,
               "{}.position_m: {:.3g} m below the ground (z points up; the ground is opaque)", ctx,
               -c.position_m.z());
    FV_REQUIRE(c.look_at_m.allFinite(), "{}.look_at_m: not finite", ctx);
    const Eigen::Vector3d d = c.look_at_m - c.position_m;
    FV_REQUIRE(d.norm() > 1e-6, "{}.look_at_m: equals position_m", ctx);
    FV_REQUIRE(d.head<2>().norm() > 1e-6 * d.norm(),
               "{}.look_at_m: straight up or down from position_m (the image's up is "
               "undefined; give rvec/tvec)",
               ctx);
  }
}

void CheckBallPhysics(const BallPhysics& p) {
  FV_REQUIRE(std::isfinite(p.gravity_mps2) && p.gravity_mps2 > 0,
             "ball.physics.gravity_mps2: must be > 0");
  FV_REQUIRE(std::isfinite(p.drag_coefficient) && p.drag_coefficient >= 0,
             "ball.physics.drag_coefficient: must be >= 0");
  FV_REQUIRE(std::isfinite(p.air_density_kgm3) && p.air_density_kgm3 >= 0,
             "ball.physics.air_density_kgm3: must be >= 0");
  FV_REQUIRE(std::isfinite(p.mass_kg) && p.mass_kg > 0, "ball.physics.mass_kg: must be > 0");
  FV_REQUIRE(std::isfinite(p.restitution) && p.restitution >= 0 && p.restitution < 1,
             "ball.physics.restitution: must be in [0, 1)");
  FV_REQUIRE(std::isfinite(p.bounce_friction) && p.bounce_friction >= 0 && p.bounce_friction <= 1,
             "ball.physics.bounce_friction: must be in [0, 1]");
  FV_REQUIRE(std::isfinite(p.rolling_resistance) && p.rolling_resistance >= 0,
             "ball.physics.rolling_resistance: must be >= 0");
  FV_REQUIRE(std::isfinite(p.min_bounce_speed_mps) && p.min_bounce_speed_mps > 0,
             "ball.physics.min_bounce_speed_mps: must be > 0");
  FV_REQUIRE(std::isfinite(p.time_step_s) && p.time_step_s >= 1e-5 && p.time_step_s <= 0.01,
             "ball.physics.time_step_s: must be in [1e-5, 0.01]");
}

// The ball's highlight and printed pattern.
void CheckBallLook(const BallSpec& ball) {
  FV_REQUIRE(std::isfinite(ball.specular) && ball.specular >= 0 && ball.specular <= 255,
             "ball.specular: must be in [0, 255] (8-bit levels)");
  FV_REQUIRE(std::isfinite(ball.shininess) && ball.shininess >= 1 && ball.shininess <= 10000,
             "ball.shininess: must be in [1, 10000]");
  const auto& names = BallPatternNames();
  FV_REQUIRE(std::find(names.begin(), names.end(), ball.pattern) != names.end(),
             "ball.pattern: '{}' is not one of {}", ball.pattern, fmt::join(names, ", "));
  CheckColour(ball.pattern_bgr, "ball.pattern_bgr");
  FV_REQUIRE(ball.orientation_rvec.allFinite(), "ball.orientation_rvec: not finite");
}

void CheckBallSpec(const BallSpec& ball) {
  FV_REQUIRE(std::isfinite(ball.diameter_m) && ball.diameter_m > 0 && ball.diameter_m < 5,
             "ball.diameter_m: must be in (0, 5)");
  CheckColour(ball.colour_bgr, "ball.colour_bgr");
  FV_REQUIRE(ball.placements.empty() || ball.kicks.empty(),
             "ball: give either placements or kicks, not both");
  FV_REQUIRE(ball.held_by < 0 || (ball.placements.empty() && ball.kicks.empty()),
             "ball.held_by: a held ball takes no placements or kicks");
  FV_REQUIRE(ball.held_by >= 0 || !ball.placements.empty() || !ball.kicks.empty(),
             "ball: needs placements, kicks or held_by (or \"enabled\": false)");
  for (size_t i = 0; i < ball.placements.size(); ++i) {
    FV_REQUIRE(ball.placements[i].allFinite(), "ball.placements[{}]: not finite", i);
  }
  FV_REQUIRE(ball.hold_frames >= 1, "ball.hold_frames: must be >= 1");
  for (size_t i = 0; i < ball.kicks.size(); ++i) {
    const KickSpec& k = ball.kicks[i];
    FV_REQUIRE(std::isfinite(k.time_s) && k.time_s >= 0, "ball.kicks[{}].time_s: must be >= 0", i);
    FV_REQUIRE(k.position_m.allFinite(), "ball.kicks[{}].position_m: not finite", i);
    FV_REQUIRE(k.position_m.z() >= ball.radius_m() - 1e-9,
               "ball.kicks[{}].position_m: z must be >= the ball radius {}", i, ball.radius_m());
    FV_REQUIRE(k.velocity_mps.allFinite() && k.velocity_mps.norm() < 100,
               "ball.kicks[{}].velocity_mps: must be finite and below 100 m/s", i);
    FV_REQUIRE(k.spin_radps.allFinite() && k.spin_radps.norm() <= 1000,
               "ball.kicks[{}].spin_radps: must be finite and at most 1000 rad/s", i);
  }
  CheckBallPhysics(ball.physics);
  CheckBallLook(ball);
}

void CheckLighting(const LightingSpec& lighting) {
  FV_REQUIRE(lighting.light_dir.allFinite() && lighting.light_dir.z() > 0.05,
             "lighting.light_dir: must point upwards (z > 0)");
  FV_REQUIRE(std::isfinite(lighting.sun_elevation_deg) && lighting.sun_elevation_deg >= 0 &&
                 lighting.sun_elevation_deg <= 90,
             "lighting.sun_elevation_deg: must be in [0, 90] (0: use light_dir)");
  FV_REQUIRE(lighting.sun_elevation_deg == 0 || lighting.sun_elevation_deg >= 3,
             "lighting.sun_elevation_deg: at least 3 deg (shadows would reach too far)");
  FV_REQUIRE(std::isfinite(lighting.sun_azimuth_deg), "lighting.sun_azimuth_deg: not finite");
  FV_REQUIRE(std::isfinite(lighting.ambient) && lighting.ambient <= 1,
             "lighting.ambient: must be in [0, 1] (or negative for the fixed shading)");
  FV_REQUIRE(std::isfinite(lighting.white_balance_amplitude) &&
                 lighting.white_balance_amplitude >= 0 && lighting.white_balance_amplitude < 0.5,
             "lighting.white_balance_amplitude: must be in [0, 0.5)");
  FV_REQUIRE(std::isfinite(lighting.white_balance_period_s) && lighting.white_balance_period_s > 0,
             "lighting.white_balance_period_s: must be > 0");
  FV_REQUIRE(std::isfinite(lighting.gain_amplitude) && lighting.gain_amplitude >= 0 &&
                 lighting.gain_amplitude < 1,
             "lighting.gain_amplitude: must be in [0, 1)");
  FV_REQUIRE(std::isfinite(lighting.period_s) && lighting.period_s > 0,
             "lighting.period_s: must be > 0");
  FV_REQUIRE(
      std::isfinite(lighting.vignetting) && lighting.vignetting >= 0 && lighting.vignetting < 1,
      "lighting.vignetting: must be in [0, 1)");
}

}  // namespace

void SceneSpec::Check() const {
  FV_REQUIRE(!field.empty(), "field: must name a built-in field or a JSON file");
  FV_REQUIRE(!cameras.empty(), "cameras: needs at least one camera");
  std::set<std::string> names;
  for (size_t i = 0; i < cameras.size(); ++i) {
    const CameraSpec& c = cameras[i];
    const std::string ctx = fmt::format("cameras[{}]", i);
    FV_REQUIRE(!c.name.empty(), "{}.name: must not be empty", ctx);
    FV_REQUIRE(c.name.find_first_of("/\\ ") == std::string::npos,
               "{}.name: '{}' must not contain '/', '\\' or spaces (it names files)", ctx, c.name);
    FV_REQUIRE(names.insert(c.name).second, "{}.name: '{}' is used twice", ctx, c.name);
    CheckCameraSpec(c, ctx);
  }
  FV_REQUIRE(std::isfinite(fps) && fps > 0 && fps <= 10000, "fps: must be in (0, 10000]");
  FV_REQUIRE(num_frames > 0 && num_frames <= 1000000, "num_frames: must be in 1..1000000");
  FV_REQUIRE(std::isfinite(exposure_s) && exposure_s >= 0 && exposure_s <= 1.0 / fps + 1e-12,
             "exposure_s: must be in [0, 1/fps]");
  if (ball.enabled) {
    CheckBallSpec(ball);
  }
  for (size_t i = 0; i < robots.size(); ++i) {
    const std::string ctx = fmt::format("robots[{}]", i);
    CheckPath(robots[i].path, ctx + ".path");
    FV_REQUIRE(std::isfinite(robots[i].radius_m) && robots[i].radius_m > 0,
               "{}.radius_m: must be > 0", ctx);
    FV_REQUIRE(std::isfinite(robots[i].height_m) && robots[i].height_m > 0,
               "{}.height_m: must be > 0", ctx);
    CheckColour(robots[i].colour_bgr, ctx + ".colour_bgr");
    FV_REQUIRE(std::isfinite(robots[i].heading_deg), "{}.heading_deg: not finite", ctx);
  }
  if (ball.enabled && ball.held_by >= 0) {
    FV_REQUIRE(ball.held_by < static_cast<int>(robots.size()) && robots[ball.held_by].handler,
               "ball.held_by: {} must index a robot with \"handler\": true", ball.held_by);
  }
  std::set<int> ids;
  for (size_t i = 0; i < people.size(); ++i) {
    const std::string ctx = fmt::format("people[{}]", i);
    FV_REQUIRE(ids.insert(people[i].id).second, "{}.id: {} is used twice", ctx, people[i].id);
    FV_REQUIRE(people[i].team >= 0 && people[i].team < static_cast<int>(teams.size()),
               "{}.team: must index teams (0..{})", ctx, static_cast<int>(teams.size()) - 1);
    CheckPath(people[i].path, ctx + ".path");
    FV_REQUIRE(
        std::isfinite(people[i].height_m) && people[i].height_m > 0.5 && people[i].height_m < 2.5,
        "{}.height_m: must be in (0.5, 2.5)", ctx);
    CheckColour(people[i].skin_bgr, ctx + ".skin_bgr");
  }
  for (size_t i = 0; i < teams.size(); ++i) {
    CheckColour(teams[i].shirt_bgr, fmt::format("teams[{}].shirt_bgr", i));
    CheckColour(teams[i].shorts_bgr, fmt::format("teams[{}].shorts_bgr", i));
  }
  for (size_t i = 0; i < cones.size(); ++i) {
    const std::string ctx = fmt::format("cones[{}]", i);
    FV_REQUIRE(cones[i].position_m.allFinite(), "{}.position_m: not finite", ctx);
    FV_REQUIRE(std::isfinite(cones[i].height_m) && cones[i].height_m > 0,
               "{}.height_m: must be > 0", ctx);
    FV_REQUIRE(std::isfinite(cones[i].base_radius_m) && cones[i].base_radius_m > 0,
               "{}.base_radius_m: must be > 0", ctx);
    CheckColour(cones[i].colour_bgr, ctx + ".colour_bgr");
  }
  CheckLighting(lighting);
  FV_REQUIRE(std::isfinite(noise_sigma) && noise_sigma >= 0 && noise_sigma <= 50,
             "noise_sigma: must be in [0, 50]");
  FV_REQUIRE(jpeg_quality >= 1 && jpeg_quality <= 100, "jpeg_quality: must be in 1..100");
  FV_REQUIRE(format == "avi" || format == "mp4" || format == "png" || format == "jpg",
             "format: must be avi, mp4, png or jpg (got '{}')", format);
  FV_REQUIRE(format != "avi" || (jpeg_quality >= 50 && jpeg_quality <= 95),
             "jpeg_quality: must be in 50..95 for \"avi\" (the MJPG writer's range; got {}); "
             "format \"jpg\" takes 1..100",
             jpeg_quality);
}

namespace {

// One camera of scene JSON.
json CameraSpecToJson(const CameraSpec& c) {
  json cj;
  cj["name"] = c.name;
  cj["width"] = c.width;
  cj["height"] = c.height;
  if (c.fx > 0) {
    cj["fx"] = c.fx;
    cj["fy"] = c.fy;
  } else {
    cj["hfov_deg"] = c.hfov_deg;
  }
  cj["distortion"] = c.distortion;
  if (c.has_rvec_tvec) {
    cj["rvec"] = util::JsonFromVector(c.rvec);
    cj["tvec"] = util::JsonFromVector(c.tvec);
  } else {
    cj["position_m"] = util::JsonFromVector(c.position_m);
    cj["look_at_m"] = util::JsonFromVector(c.look_at_m);
  }
  return cj;
}

// The ball of scene JSON (appearance keys only when not the defaults).
json BallSpecToJson(const BallSpec& ball) {
  json b;
  b["enabled"] = ball.enabled;
  b["diameter_m"] = ball.diameter_m;
  b["colour_bgr"] = util::JsonFromVector(ball.colour_bgr);
  b["placements"] = json::array();
  for (const auto& p : ball.placements) b["placements"].push_back(util::JsonFromVector(p));
  b["hold_frames"] = ball.hold_frames;
  b["kicks"] = json::array();
  for (const auto& k : ball.kicks) {
    json kj = {{"time_s", k.time_s},
               {"position_m", util::JsonFromVector(k.position_m)},
               {"velocity_mps", util::JsonFromVector(k.velocity_mps)}};
    if (!k.spin_radps.isZero()) kj["spin_radps"] = util::JsonFromVector(k.spin_radps);
    b["kicks"].push_back(kj);
  }
  // The appearance keys are written when they differ from the defaults (older scenes unchanged).
  const BallSpec db;
  if (ball.held_by >= 0) b["held_by"] = ball.held_by;
  if (ball.specular != db.specular) b["specular"] = ball.specular;
  if (ball.shininess != db.shininess) b["shininess"] = ball.shininess;
  if (ball.pattern != db.pattern) {
    b["pattern"] = ball.pattern;
    b["pattern_bgr"] = util::JsonFromVector(ball.pattern_bgr);
  }
  if (!ball.orientation_rvec.isZero()) {
    b["orientation_rvec"] = util::JsonFromVector(ball.orientation_rvec);
  }
  const BallPhysics& p = ball.physics;
  b["physics"] = {{"gravity_mps2", p.gravity_mps2},
                  {"drag_coefficient", p.drag_coefficient},
                  {"air_density_kgm3", p.air_density_kgm3},
                  {"mass_kg", p.mass_kg},
                  {"restitution", p.restitution},
                  {"bounce_friction", p.bounce_friction},
                  {"rolling_resistance", p.rolling_resistance},
                  {"min_bounce_speed_mps", p.min_bounce_speed_mps},
                  {"time_step_s", p.time_step_s}};
  return b;
}

}  // namespace

json SceneSpecToJson(const SceneSpec& s) {
  json j;
  j["field"] = s.field;
  j["fps"] = s.fps;
  j["num_frames"] = s.num_frames;
  j["seed"] = s.seed;
  j["exposure_s"] = s.exposure_s;
  j["cameras"] = json::array();
  for (const auto& c : s.cameras) j["cameras"].push_back(CameraSpecToJson(c));
  j["ball"] = BallSpecToJson(s.ball);
  j["robots"] = json::array();
  for (const auto& r : s.robots) {
    json rj = {{"path", PathToJson(r.path)},
               {"radius_m", r.radius_m},
               {"height_m", r.height_m},
               {"colour_bgr", util::JsonFromVector(r.colour_bgr)}};
    if (r.handler) {
      rj["handler"] = true;
      rj["heading_deg"] = r.heading_deg;
    }
    j["robots"].push_back(rj);
  }
  j["people"] = json::array();
  for (const auto& p : s.people) {
    j["people"].push_back({{"id", p.id},
                           {"team", p.team},
                           {"path", PathToJson(p.path)},
                           {"height_m", p.height_m},
                           {"skin_bgr", util::JsonFromVector(p.skin_bgr)}});
  }
  j["teams"] = json::array();
  for (const auto& t : s.teams) {
    j["teams"].push_back({{"name", t.name},
                          {"shirt_bgr", util::JsonFromVector(t.shirt_bgr)},
                          {"shorts_bgr", util::JsonFromVector(t.shorts_bgr)}});
  }
  j["cones"] = json::array();
  for (const auto& c : s.cones) {
    j["cones"].push_back({{"position_m", util::JsonFromVector(c.position_m)},
                          {"height_m", c.height_m},
                          {"base_radius_m", c.base_radius_m},
                          {"colour_bgr", util::JsonFromVector(c.colour_bgr)}});
  }
  j["lighting"] = {{"light_dir", util::JsonFromVector(s.lighting.light_dir)},
                   {"gain_amplitude", s.lighting.gain_amplitude},
                   {"period_s", s.lighting.period_s},
                   {"vignetting", s.lighting.vignetting},
                   {"shadows", s.lighting.shadows}};
  if (s.lighting.sun_elevation_deg > 0) {
    j["lighting"]["sun_elevation_deg"] = s.lighting.sun_elevation_deg;
    j["lighting"]["sun_azimuth_deg"] = s.lighting.sun_azimuth_deg;
  }
  if (s.lighting.ambient >= 0) j["lighting"]["ambient"] = s.lighting.ambient;
  if (s.lighting.white_balance_amplitude > 0) {
    j["lighting"]["white_balance_amplitude"] = s.lighting.white_balance_amplitude;
    j["lighting"]["white_balance_period_s"] = s.lighting.white_balance_period_s;
  }

  j["noise_sigma"] = s.noise_sigma;
  j["jpeg_quality"] = s.jpeg_quality;
  j["format"] = s.format;
  return j;
}

SceneSpec SceneSpecFromJson(const json& j, const std::string& context) {
  try {
    util::JsonKnownKeys(j, "",
                        {"field", "fps", "num_frames", "duration_s", "seed", "exposure_s",
                         "cameras", "ball", "robots", "people", "teams", "cones", "lighting",
                         "noise_sigma", "jpeg_quality", "format"});
    SceneSpec s;
    s.field = util::JsonString(j, "field", "", s.field);
    s.fps = util::JsonNumber(j, "fps", "", s.fps);
    FV_REQUIRE(s.fps > 0, "fps: must be > 0");
    if (util::JsonHas(j, "num_frames")) {
      s.num_frames = util::JsonInt(j, "num_frames", "", s.num_frames);
    } else if (util::JsonHas(j, "duration_s")) {
      const double d = util::JsonNumber(j, "duration_s", "", 1.0);
      FV_REQUIRE(d > 0 && d < 1e5, "duration_s: must be in (0, 1e5)");
      s.num_frames = std::max(1, static_cast<int>(std::lround(d * s.fps)));
    }
    if (util::JsonHas(j, "seed")) {
      FV_REQUIRE(j["seed"].is_number_unsigned() || j["seed"].is_number_integer(),
                 "seed: must be a non-negative integer");
      FV_REQUIRE(!j["seed"].is_number_integer() || j["seed"].get<int64_t>() >= 0,
                 "seed: must be a non-negative integer");
      s.seed = j["seed"].get<uint64_t>();
    }
    s.exposure_s = util::JsonNumber(j, "exposure_s", "", s.exposure_s);
    const json& cams = util::JsonArray(j, "cameras", "");
    s.cameras.clear();
    for (size_t i = 0; i < cams.size(); ++i) s.cameras.push_back(CameraSpecFromJson(cams[i], i));
    if (util::JsonHas(j, "ball")) {
      s.ball = BallSpecFromJson(util::JsonObject(j, "ball", ""), s.ball);
    } else {
      s.ball.enabled = false;
    }
    const json& robots = util::JsonArray(j, "robots", "");
    for (size_t i = 0; i < robots.size(); ++i) s.robots.push_back(RobotSpecFromJson(robots[i], i));
    const json& people = util::JsonArray(j, "people", "");
    for (size_t i = 0; i < people.size(); ++i) s.people.push_back(PersonSpecFromJson(people[i], i));
    if (util::JsonHas(j, "teams")) {
      const json& teams = util::JsonArray(j, "teams", "");
      s.teams.clear();
      for (size_t i = 0; i < teams.size(); ++i) s.teams.push_back(TeamSpecFromJson(teams[i], i));
    }
    const json& cones = util::JsonArray(j, "cones", "");
    for (size_t i = 0; i < cones.size(); ++i) s.cones.push_back(ConeSpecFromJson(cones[i], i));
    if (util::JsonHas(j, "lighting")) {
      s.lighting = LightingSpecFromJson(util::JsonObject(j, "lighting", ""), s.lighting);
    }
    s.noise_sigma = util::JsonNumber(j, "noise_sigma", "", s.noise_sigma);
    s.jpeg_quality = util::JsonInt(j, "jpeg_quality", "", s.jpeg_quality);
    s.format = util::JsonString(j, "format", "", s.format);
    s.Check();
    return s;
  } catch (const Error& e) {
    throw Error(context.empty() ? std::string(e.what()) : context + ": " + e.what());
  } catch (const json::exception& e) {
    throw Error(fmt::format("{}: {}", context.empty() ? "scene" : context, e.what()));
  }
}

SceneSpec ReadSceneSpec(const std::string& path) {
  return SceneSpecFromJson(util::ReadJsonFile(path, "scene"), path);
}

std::vector<std::string> PresetNames() {
  return {"static", "kick", "players", "demo", "low-sun", "low-sun-kick", "fisheye", "held"};
}

std::vector<std::string> BallPatternNames() { return {"none", "print", "pentagons"}; }

Eigen::Vector3d LightingSpec::Direction() const {
  if (sun_elevation_deg <= 0) return light_dir.normalized();
  const double e = sun_elevation_deg * M_PI / 180, a = sun_azimuth_deg * M_PI / 180;
  return Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
}

std::vector<double> FisheyeDistortion() {
  // Least-squares fit of r (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6) to
  // atan(r) for 0..82 deg off axis (within 0.03 deg up to 80 deg; monotonic to 90 deg).
  return {0.43968398, 0.022700659, 0.0, 0.0, 7.7899975e-05, 0.76687624, 0.093428723, 0.0013553043};
}

double FisheyeFocalPx(int width, double hfov_deg) {
  FV_REQUIRE(width > 0 && hfov_deg > 1 && hfov_deg < 180,
             "fisheye: width must be > 0 and hfov_deg in (1, 180) (got {}, {})", width, hfov_deg);
  return 0.5 * width / (0.5 * hfov_deg * M_PI / 180);
}

SceneSpec Preset(const std::string& name, uint64_t seed) {
  SceneSpec s;
  if (name == "static") {
    s = StaticPreset(seed);
  } else if (name == "kick" || name == "demo") {
    s = KickPreset(seed);
  } else if (name == "players") {
    s = PlayersPreset(seed);
  } else if (name == "low-sun") {
    s = StaticPreset(seed);
    ApplyLowSun(s);
  } else if (name == "low-sun-kick") {
    s = LowSunKickPreset(seed);
  } else if (name == "fisheye") {
    s = FisheyePreset(seed);
  } else if (name == "held") {
    s = HeldPreset(seed);
  } else {
    Throw("unknown preset '{}' (known: {})", name, fmt::join(PresetNames(), ", "));
  }
  s.Check();
  return s;
}

void ResizeCameras(SceneSpec& spec, int width, int height) {
  FV_REQUIRE(width > 0 && height > 0, "image size must be positive (got {}x{})", width, height);
  for (auto& c : spec.cameras) {
    if (c.fx > 0) {
      c.fx *= static_cast<double>(width) / c.width;
      c.fy *= static_cast<double>(height) / c.height;
    }
    c.width = width;
    c.height = height;
  }
}

json FlightsToJson(const std::vector<Flight>& flights) {
  json a = json::array();
  for (const auto& f : flights) {
    a.push_back({{"t_start_s", f.t_start_s},
                 {"t_end_s", f.t_end_s},
                 {"origin", util::JsonFromVector(f.origin)},
                 {"landing", util::JsonFromVector(f.landing)},
                 {"apex", util::JsonFromVector(f.apex)},
                 {"v0_mps", util::JsonFromVector(f.v0_mps)}});
  }
  return a;
}

}  // namespace fv::synth
