#include "fieldvision/plan/optimize.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/progress.h"
#include "fieldvision/util/random.h"

namespace fv::plan {
namespace {

using nlohmann::json;

Eigen::Vector3d ReadPoint(const json& j, const std::string& ctx) {
  FV_REQUIRE(j.is_array() && j.size() == 3, "{}: expected [x, y, z] in metres", ctx);
  Eigen::Vector3d p;
  for (int i = 0; i < 3; ++i) {
    FV_REQUIRE(j[i].is_number(), "{}: element {} is not a number", ctx, i);
    p[i] = j[i].get<double>();
    FV_REQUIRE(std::isfinite(p[i]) && std::abs(p[i]) <= 1e4,
               "{}: element {} is not a coordinate within 10 km of the field centre (got {})", ctx,
               i, p[i]);
  }
  return p;
}

struct CamState {
  int place = 0;
  double t = 0;
  Eigen::Vector2d aim = Eigen::Vector2d::Zero();
};

class Search {
 public:
  Search(const field::FieldModel& field, const std::vector<MountPlace>& mounts,
         const camera::Camera& model, const CoverageOptions& coverage,
         const OptimizeOptions& options)
      : field_(field), mounts_(mounts), model_(model), coverage_(coverage), options_(options) {
    coverage_.grid_step_m = options.grid_step_m;
    coverage_.progress = false;
  }

  std::vector<camera::Camera> Cameras(const std::vector<CamState>& state) const {
    std::vector<camera::Camera> cams;
    for (size_t k = 0; k < state.size(); ++k) {
      const Eigen::Vector3d eye = mounts_[state[k].place].At(state[k].t);
      const Eigen::Vector3d target(state[k].aim.x(), state[k].aim.y(), options_.aim_height_m);
      camera::Camera c = model_;
      c.name = fmt::format("cam{}", k + 1);
      c.cam_from_world = geometry::Rigid3d::LookAt(eye, target);
      c.has_pose = true;
      cams.push_back(std::move(c));
    }
    return cams;
  }

  double Score(const std::vector<CamState>& state) {
    ++evaluations_;
    return EvaluateCoverage(Cameras(state), field_, coverage_).score();
  }

  // Cameras spread evenly along the segments (or over the points), aimed at the centre.
  std::vector<CamState> EvenStart() const {
    std::vector<CamState> s(options_.num_cameras);
    double total = 0;
    for (const auto& m : mounts_) total += m.LengthM();
    for (int k = 0; k < options_.num_cameras; ++k) {
      if (total <= 0) {
        s[k].place = k % static_cast<int>(mounts_.size());
        continue;
      }
      double along = total * k / options_.num_cameras;
      for (size_t p = 0; p < mounts_.size(); ++p) {
        const double len = mounts_[p].LengthM();
        if (len <= 0) continue;
        s[k].place = static_cast<int>(p);
        if (along <= len) {
          s[k].t = along / len;
          break;
        }
        along -= len;
        s[k].t = 1.0;
      }
    }
    return s;
  }

  std::vector<CamState> RandomStart(util::Rng& rng) const {
    std::vector<CamState> s(options_.num_cameras);
    for (auto& c : s) {
      c.place = rng.UniformInt(0, static_cast<int>(mounts_.size()) - 1);
      c.t = rng.Uniform();
      c.aim = {rng.Uniform(-0.25, 0.25) * field_.length_m,
               rng.Uniform(-0.25, 0.25) * field_.width_m};
    }
    return s;
  }

  void Move(std::vector<CamState>& s, util::Rng& rng, double shrink) const {
    CamState& c = s[rng.UniformInt(0, static_cast<int>(s.size()) - 1)];
    const double u = rng.Uniform();
    const bool move_place = u < 0.55, move_aim = u >= 0.45;
    if (move_place) {
      if (rng.Uniform() < 0.1 * shrink + 0.02) {
        c.place = rng.UniformInt(0, static_cast<int>(mounts_.size()) - 1);
        c.t = rng.Uniform();
      } else {
        const double len = mounts_[c.place].LengthM();
        if (len > 0) {
          double t = c.t + rng.Normal(0, options_.move_step_m * shrink / len);
          t = std::fmod(std::abs(t), 2.0);  // reflect at the ends
          c.t = t > 1.0 ? 2.0 - t : t;
        }
      }
    }
    if (move_aim) {
      const double hx = 0.5 * field_.length_m, hy = 0.5 * field_.width_m;
      c.aim.x() = std::clamp(c.aim.x() + rng.Normal(0, options_.aim_step_m * shrink), -hx, hx);
      c.aim.y() = std::clamp(c.aim.y() + rng.Normal(0, options_.aim_step_m * shrink), -hy, hy);
    }
  }

  int evaluations() const { return evaluations_; }

 private:
  const field::FieldModel& field_;
  const std::vector<MountPlace>& mounts_;
  const camera::Camera& model_;
  CoverageOptions coverage_;
  const OptimizeOptions& options_;
  int evaluations_ = 0;
};

}  // namespace

std::vector<MountPlace> PerimeterMounts(const field::FieldModel& field, double offset_m,
                                        double height_m) {
  FV_REQUIRE(std::isfinite(offset_m) && offset_m >= 0, "perimeter offset must be >= 0 (got {})",
             offset_m);
  FV_REQUIRE(std::isfinite(height_m) && height_m > 0, "mount height must be > 0 (got {})",
             height_m);
  const double x = 0.5 * field.length_m + offset_m, y = 0.5 * field.width_m + offset_m;
  const Eigen::Vector3d c00(-x, -y, height_m), c10(x, -y, height_m), c11(x, y, height_m),
      c01(-x, y, height_m);
  return {
      {"side y-", c00, c10}, {"side x+", c10, c11}, {"side y+", c11, c01}, {"side x-", c01, c00}};
}

std::vector<MountPlace> MountsFromJson(const json& j, const std::string& context) {
  FV_REQUIRE(j.is_object() && j.contains("mounts"), "{}: missing key 'mounts'", context);
  FV_REQUIRE(j["mounts"].is_array(), "{}: key 'mounts' must be an array", context);
  std::vector<MountPlace> mounts;
  for (size_t i = 0; i < j["mounts"].size(); ++i) {
    const json& m = j["mounts"][i];
    const std::string ctx = fmt::format("{}: mounts[{}]", context, i);
    FV_REQUIRE(m.is_object(), "{}: must be an object", ctx);
    MountPlace place;
    place.name = m.contains("name") && m["name"].is_string() ? m["name"].get<std::string>()
                                                             : fmt::format("mount{}", i + 1);
    FV_REQUIRE(m.contains("point") != m.contains("line"), "{}: give one of 'point' or 'line'", ctx);
    if (m.contains("point")) {
      place.a = place.b = ReadPoint(m["point"], ctx + ".point");
    } else {
      FV_REQUIRE(m["line"].is_array() && m["line"].size() == 2,
                 "{}: key 'line' must be [[x, y, z], [x, y, z]]", ctx);
      place.a = ReadPoint(m["line"][0], ctx + ".line[0]");
      place.b = ReadPoint(m["line"][1], ctx + ".line[1]");
    }
    // The ground is opaque (z up, the field at z = 0): cameras there saw through it.
    FV_REQUIRE(place.a.z() >= 0 && place.b.z() >= 0,
               "{}: {:.3g} m below the ground (z points up, the field at z = 0)", ctx,
               -std::min(place.a.z(), place.b.z()));
    mounts.push_back(place);
  }
  FV_REQUIRE(!mounts.empty(), "{}: no mounting places", context);
  return mounts;
}

std::vector<MountPlace> ReadMountsJson(const std::string& path) {
  return MountsFromJson(util::ReadJsonFile(path, "mounts"), "mounts file '" + path + "'");
}

void OptimizeOptions::Check() const {
  FV_REQUIRE(num_cameras >= 2 && num_cameras <= 32,
             "num_cameras must be in [2, 32] (got {}): the ball is placed from two cameras or more",
             num_cameras);
  CheckPositive(grid_step_m, "grid_step_m");
  FV_REQUIRE(iterations >= 0 && iterations <= 1000000, "iterations must be in [0, 1e6] (got {})",
             iterations);
  FV_REQUIRE(restarts >= 1 && restarts <= 100, "restarts must be in [1, 100] (got {})", restarts);
  CheckPositive(start_temperature, "start_temperature");
  CheckPositive(move_step_m, "move_step_m");
  CheckPositive(aim_step_m, "aim_step_m");
  CheckFinite(aim_height_m, "aim_height_m");
}

double RigScore(const std::vector<camera::Camera>& cameras, const field::FieldModel& field,
                const CoverageOptions& coverage, double grid_step_m) {
  CoverageOptions o = coverage;
  o.grid_step_m = grid_step_m;
  o.progress = false;
  return EvaluateCoverage(cameras, field, o).score();
}

OptimizeResult OptimizeRig(const field::FieldModel& field, const std::vector<MountPlace>& mounts,
                           const camera::Camera& model, const CoverageOptions& coverage,
                           const OptimizeOptions& options) {
  options.Check();
  coverage.Check();
  FV_REQUIRE(!mounts.empty(), "optimize: no mounting places");
  for (const auto& m : mounts) {
    FV_REQUIRE(m.a.allFinite() && m.b.allFinite(), "optimize: mount '{}' is not finite", m.name);
  }
  camera::Camera cam_model = model;
  cam_model.has_pose = false;
  cam_model.Check("optimize: camera model");
  const auto start_time = std::chrono::steady_clock::now();
  Search search(field, mounts, cam_model, coverage, options);
  util::Rng rng(options.seed);
  OptimizeResult result;
  std::vector<CamState> best;
  double best_score = -1e300;
  util::Progress progress("optimize", static_cast<long long>(options.restarts) * options.iterations,
                          "steps", options.progress);
  for (int r = 0; r < options.restarts; ++r) {
    std::vector<CamState> current = r == 0 ? search.EvenStart() : search.RandomStart(rng);
    double current_score = search.Score(current);
    if (r == 0) result.start_score = current_score;
    if (current_score > best_score) {
      best_score = current_score;
      best = current;
    }
    for (int it = 0; it < options.iterations; ++it) {
      const double frac = options.iterations > 1 ? double(it) / (options.iterations - 1) : 1.0;
      const double temperature = options.start_temperature * std::pow(1e-3, frac);
      const double shrink = std::pow(0.05, frac);
      std::vector<CamState> candidate = current;
      search.Move(candidate, rng, shrink);
      const double s = search.Score(candidate);
      if (s >= current_score || rng.Uniform() < std::exp((s - current_score) / temperature)) {
        current = std::move(candidate);
        current_score = s;
        if (current_score > best_score) {
          best_score = current_score;
          best = current;
        }
      }
      progress.Update(static_cast<long long>(r) * options.iterations + it + 1);
    }
  }
  progress.Finish();
  // The score can be negative for a rig that sees the field (a large error weight): what says
  // the search found nothing is the share seen from two cameras at a good angle.
  const CoverageResult best_coverage = EvaluateCoverage(search.Cameras(best), field, coverage);
  FV_REQUIRE(!best_coverage.layers.empty() && best_coverage.layers[0].fraction_good > 0,
             "optimize: no placement of {} cameras on these mounts sees any of the field from two "
             "of them at a usable angle (check the mounts' places and heights, the lens' field of "
             "view and the number of cameras)",
             options.num_cameras);
  result.rig.name =
      fmt::format("optimized rig ({} cameras, seed {})", options.num_cameras, options.seed);
  result.rig.cameras = search.Cameras(best);
  result.score = best_score;
  result.evaluations = search.evaluations();
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

std::string OptimizeResult::Summary() const {
  std::string s = fmt::format(
      "optimized {} cameras: score {:.4f} on the search grid (evenly spread start {:.4f}), {} "
      "evaluations in {:.1f} s\n",
      rig.cameras.size(), score, start_score, evaluations, seconds);
  for (const camera::Camera& c : rig.cameras) {
    const Eigen::Vector3d p = c.CentreInWorld();
    const Eigen::Vector3d axis = c.AxisInWorld();
    Eigen::Vector3d aim = p + 10 * axis;
    if (axis.z() < -1e-6) aim = p + (-p.z() / axis.z()) * axis;
    s += fmt::format("  {:<6s} at ({:6.2f}, {:6.2f}, {:5.2f}) m aimed at ({:6.2f}, {:6.2f}) m\n",
                     c.name, p.x(), p.y(), p.z(), aim.x(), aim.y());
  }
  return s;
}

}  // namespace fv::plan
