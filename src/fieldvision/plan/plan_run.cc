#include "fieldvision/plan/plan_run.h"

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "fieldvision/camera/pose_range.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/output_path.h"

namespace fv::plan {
namespace {

using nlohmann::json;

json Finite(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json LayerJson(const CoverageLayer& L) {
  return {
      {"height_m", L.height_m},
      {"grid", {{"nx", L.nx}, {"ny", L.ny}, {"step_x_m", L.step_x_m}, {"step_y_m", L.step_y_m}}},
      {"fraction_exactly", L.fraction_exactly},
      {"fraction_at_least_2", L.fraction_at_least_2},
      {"fraction_good", L.fraction_good},
      {"angle",
       {{"median_deg", Finite(L.angle_median_deg)},
        {"fraction_good_of_at_least_2", Finite(L.fraction_angle_good_of_2)}}},
      {"error",
       {{"median_m", Finite(L.err_median_m)},
        {"p95_m", Finite(L.err_p95_m)},
        {"max_m", Finite(L.err_max_m)},
        {"max_axis_max_m", Finite(L.err_max_axis_max_m)}}},
      {"score", L.score}};
}

}  // namespace

void PlanRunOptions::Check() const {
  FV_REQUIRE(!out_dir.empty(), "plan: --out is required");
  if (!optimize) {
    FV_REQUIRE(rig_path.empty() != camera_paths.empty(),
               "plan: give either --rig RIG.json or --camera CAM.yaml (one or more)");
  } else {
    FV_REQUIRE(camera_paths.empty() || rig_path.empty(),
               "plan: give at most one of --rig and --camera with --optimize");
    search.Check();
    FV_REQUIRE(image_width > 0 && image_height > 0, "plan: image size must be positive");
    CheckInRange(hfov_deg, 1, 179, "hfov_deg");
    CheckNonNegative(perimeter_offset_m, "perimeter_offset_m");
    CheckPositive(mount_height_m, "mount_height_m");
  }
  coverage.Check();
  map.Check();
}

namespace {

// The rig given by --rig or --camera, if any; a camera kilometres away is refused.
std::optional<Rig> LoadGivenRig(const PlanRunOptions& options) {
  std::optional<Rig> given;
  if (!options.rig_path.empty()) given = ReadRigJson(options.rig_path);
  if (!options.camera_paths.empty()) given = RigFromCameraFiles(options.camera_paths);
  if (!given) return given;
  // A camera kilometres away sees nothing and would only stretch the maps.
  for (const camera::Camera& c : given->cameras) {
    camera::CheckCameraNearOrigin(
        c, "plan: " + (options.rig_path.empty() ? std::string("--camera") : options.rig_path));
  }
  return given;
}

std::string OutPath(const PlanRunOptions& options, const std::string& name) {
  return (std::filesystem::path(options.out_dir) / name).string();
}

// The maps drawn for each layer, by the stem of their file names.
constexpr std::array<std::pair<CoverageMapKind, const char*>, 3> kMapKinds = {
    {{CoverageMapKind::kCount, "coverage"},
     {CoverageMapKind::kAngle, "angle"},
     {CoverageMapKind::kError, "error"}}};

// A map's file: STEM.png for the ground layer, STEM_above.png for the one above it.
std::string MapFileName(const char* stem, size_t layer) {
  return std::string(stem) + (layer == 0 ? "" : "_above") + ".png";
}

// The files RunPlan writes into out_dir (rig.json only with --optimize: without it a rig.json
// there may be the input).
std::vector<std::string> OutputNames(const PlanRunOptions& options) {
  std::vector<std::string> names = {"coverage.json"};
  const size_t layers = options.coverage.height_above_m > 0 ? 2 : 1;
  for (size_t l = 0; l < layers; ++l) {
    for (const auto& [kind, stem] : kMapKinds) names.push_back(MapFileName(stem, l));
  }
  if (options.optimize) names.push_back("rig.json");
  return names;
}

// --optimize: searches a rig over the mounting places, scores a given rig the same way and
// writes rig.json; returns the summary lines.
std::string OptimizeStage(const PlanRunOptions& options, const field::FieldModel& field,
                          const std::string& field_spec, const std::optional<Rig>& given,
                          PlanRunResult& result) {
  std::string summary;
  const std::vector<MountPlace> mounts =
      options.mounts_path.empty()
          ? PerimeterMounts(field, options.perimeter_offset_m, options.mount_height_m)
          : ReadMountsJson(options.mounts_path);
  const camera::Camera model =
      given ? given->cameras.front()
            : camera::Camera::FromFov(options.image_width, options.image_height, options.hfov_deg);
  OptimizeResult opt = OptimizeRig(field, mounts, model, options.coverage, options.search);
  summary += opt.Summary();
  if (given) {
    result.given_rig_search_score =
        RigScore(given->cameras, field, options.coverage, options.search.grid_step_m);
    summary += fmt::format("given rig '{}': score {:.4f} on the search grid\n", given->name,
                           *result.given_rig_search_score);
  }
  result.rig = opt.rig;
  // The field by name, or a field file by its path from the rig file's folder (where the rig
  // reader looks for it).
  result.rig.field = field_spec;
  if (std::filesystem::is_regular_file(field_spec)) {
    std::error_code ec;
    const std::filesystem::path from_rig = std::filesystem::relative(
        std::filesystem::absolute(field_spec), std::filesystem::absolute(options.out_dir), ec);
    result.rig.field =
        ec || from_rig.empty() ? std::filesystem::absolute(field_spec).string() : from_rig.string();
  }
  result.optimized = std::move(opt);
  WriteRigJson(result.rig, OutPath(options, "rig.json"));
  result.files.push_back(OutPath(options, "rig.json"));
  return summary;
}

// The count, angle and error maps of every layer.
void WriteCoverageMaps(const PlanRunOptions& options, const field::FieldModel& field,
                       PlanRunResult& result) {
  for (size_t l = 0; l < result.coverage.layers.size(); ++l) {
    CoverageMapOptions map = options.map;
    // Both layers' error maps on the ground layer's scale so they compare.
    if (map.err_scale_m <= 0 && std::isfinite(result.coverage.layers[0].err_max_m)) {
      map.err_scale_m = result.coverage.layers[0].err_max_m;
    }
    for (const auto& [kind, stem] : kMapKinds) {
      const std::string file = OutPath(options, MapFileName(stem, l));
      io::WriteImage(file, DrawCoverageMap(result.coverage.layers[l], kind, result.rig.cameras,
                                           field, options.coverage, map));
      result.files.push_back(file);
    }
  }
}

}  // namespace

json CoverageJson(const PlanRunResult& result, const field::FieldModel& field,
                  const PlanRunOptions& options) {
  const CoverageOptions& co = options.coverage;
  const CoverageLayer& ground = result.coverage.layers[0];
  json j;
  j["field"] = field.name;
  j["rig"] = result.rig.name;
  j["num_cameras"] = result.rig.cameras.size();
  j["cameras"] = json::array();
  for (const camera::Camera& c : result.rig.cameras) {
    j["cameras"].push_back(
        {{"name", c.name}, {"position", util::JsonFromVector(c.CentreInWorld())}});
  }
  j["options"] = {{"grid_step_m", co.grid_step_m},
                  {"include_surround", co.include_surround},
                  {"ball_diameter_m", co.ball_diameter_m},
                  {"height_above_m", co.height_above_m},
                  {"min_ball_px", co.min_ball_px},
                  {"margin_px", co.margin_px},
                  {"pixel_noise_px", co.pixel_noise_px},
                  {"good_angle_min_deg", co.good_angle_min_deg},
                  {"good_angle_max_deg", co.good_angle_max_deg},
                  {"error_weight_per_m", co.error_weight_per_m}};
  // The ball-height layer at the top level: fraction_exactly[k] = share seen by exactly k.
  const json g = LayerJson(ground);
  for (auto it = g.begin(); it != g.end(); ++it) j[it.key()] = it.value();
  j["layers"] = json::array();
  for (const auto& L : result.coverage.layers) j["layers"].push_back(LayerJson(L));
  j["rig_score"] =
      result.coverage.score();  // the mean of the layers' scores (what --optimize raises)
  if (result.optimized) {
    j["optimize"] = {{"search_grid_step_m", options.search.grid_step_m},
                     {"search_score", result.optimized->score},
                     {"even_start_search_score", result.optimized->start_score},
                     {"evaluations", result.optimized->evaluations},
                     {"seconds", result.optimized->seconds},
                     {"seed", options.search.seed}};
    if (result.given_rig_score) {
      j["optimize"]["given_rig_search_score"] = *result.given_rig_search_score;
      j["optimize"]["given_rig_score"] = *result.given_rig_score;
    }
  }
  return j;
}

namespace {

// What makes the table's counts mean less than they seem: one camera (no 3D), or two cameras at
// one place looking one way (the same camera given twice: counted as two, "seen by >= 2" at 0
// degrees).
std::string RigWarnings(const Rig& rig) {
  std::string w;
  const auto& cams = rig.cameras;
  if (cams.size() == 1) w += "warning: one camera: the ball is placed in 3D from two or more\n";
  for (size_t a = 0; a < cams.size(); ++a) {
    for (size_t b = a + 1; b < cams.size(); ++b) {
      const Eigen::Vector3d axis_a = cams[a].AxisInWorld();
      const Eigen::Vector3d axis_b = cams[b].AxisInWorld();
      if ((cams[a].CentreInWorld() - cams[b].CentreInWorld()).norm() < 0.05 &&
          axis_a.dot(axis_b) > std::cos(2.0 * M_PI / 180.0)) {
        w += fmt::format(
            "warning: cameras '{}' and '{}' stand at one place looking one way: they count as two "
            "cameras but see nothing one does not\n",
            cams[a].name, cams[b].name);
      }
    }
  }
  return w;
}

// The field of --field, else the rig file's, else robocup-msl.
std::string FieldOfRun(const PlanRunOptions& options, const std::optional<Rig>& given) {
  if (!options.field.empty()) return options.field;
  return given && !given->field.empty() ? given->field : "robocup-msl";
}

}  // namespace

PlanRunResult RunPlan(const PlanRunOptions& options) {
  options.Check();
  // The options' own checks before the cameras are read, unless the rig file names the field.
  std::optional<Rig> given;
  if (options.field.empty() && !options.rig_path.empty()) given = LoadGivenRig(options);
  const std::string field_spec = FieldOfRun(options, given);
  const field::FieldModel field = field::LoadField(field_spec);
  CheckCoverageGrid(field, options.coverage, "--step");
  if (options.optimize) {
    CoverageOptions search_grid = options.coverage;
    search_grid.grid_step_m = options.search.grid_step_m;
    CheckCoverageGrid(field, search_grid, "--search-step");
  }
  std::string summary;
  if (!given) {
    given = LoadGivenRig(options);
    if (given && !given->field.empty() && given->field != options.field &&
        !util::SameFile(given->field, options.field)) {
      summary += fmt::format("note: --field {} used; the rig file names field {}\n", options.field,
                             given->field);
    }
  }
  PlanRunResult result;
  // No file this run may write replaces one of its inputs (--optimize --rig DIR/rig.json --out
  // DIR replaced the user's rig).
  const std::vector<std::string> inputs =
      util::PathList(options.rig_path, options.camera_paths, options.mounts_path, options.field);
  for (const std::string& name : OutputNames(options)) {
    util::CheckOutputPath(OutPath(options, name), inputs, "--out");
  }
  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  FV_REQUIRE(std::filesystem::is_directory(options.out_dir), "cannot create output folder '{}'",
             options.out_dir);
  if (options.optimize) {
    summary += OptimizeStage(options, field, field_spec, given, result);
  } else {
    result.rig = *given;
  }
  result.coverage = EvaluateCoverage(result.rig.cameras, field, options.coverage);
  if (options.optimize && given) {
    result.given_rig_score = EvaluateCoverage(given->cameras, field, options.coverage).score();
  }
  summary += fmt::format("rig '{}', {} camera{}, field {} ({:.2f} x {:.2f} m)\n", result.rig.name,
                         result.rig.cameras.size(), result.rig.cameras.size() == 1 ? "" : "s",
                         field.name, field.length_m, field.width_m);
  summary += result.coverage.Summary();
  summary += RigWarnings(result.rig);
  if (result.given_rig_score) {
    summary += fmt::format("score on this grid: optimized {:.4f}, given rig {:.4f}\n",
                           result.coverage.score(), *result.given_rig_score);
  }
  WriteCoverageMaps(options, field, result);
  const std::string json_path = OutPath(options, "coverage.json");
  util::WriteTextFile(json_path, CoverageJson(result, field, options).dump(2) + "\n",
                      "coverage file");
  result.files.push_back(json_path);
  summary += fmt::format("wrote {} files to {}\n", result.files.size(), options.out_dir);
  result.summary = summary;
  return result;
}

}  // namespace fv::plan
