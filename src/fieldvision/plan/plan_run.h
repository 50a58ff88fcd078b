// `fieldvision plan`: loads a rig (rig JSON or camera YAMLs) and a field, evaluates coverage,
// pair angles and expected error (coverage.h), writes DIR/coverage.json and colour maps
// (coverage_map.h) and returns a summary table; with `optimize`, first searches a rig over the
// mounting places (optimize.h) and writes it as DIR/rig.json.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldvision/plan/coverage.h"
#include "fieldvision/plan/coverage_map.h"
#include "fieldvision/plan/optimize.h"
#include "fieldvision/plan/rig_json.h"

namespace fv::plan {

struct PlanRunOptions {
  std::string rig_path;                   // a rig JSON file, or
  std::vector<std::string> camera_paths;  // camera YAML files (with poses)
  // Built-in name or field JSON; empty: the rig file's `field`, else robocup-msl.
  std::string field;
  std::string out_dir;  // created if missing
  CoverageOptions coverage;
  CoverageMapOptions map;

  // Search a rig instead (a given rig is scored the same way for comparison and its first
  // camera's intrinsics are used; otherwise image_width x image_height with hfov_deg).
  bool optimize = false;
  OptimizeOptions search;
  std::string mounts_path;          // mounting places JSON (optimize.h); empty: the perimeter
  double perimeter_offset_m = 1.0;  // perimeter rectangle this far outside the lines
  double mount_height_m = 4.0;      // at this height
  int image_width = 1280;
  int image_height = 960;
  double hfov_deg = 80.0;

  void Check() const;
};

struct PlanRunResult {
  Rig rig;                  // the rig evaluated (the optimized one with `optimize`)
  CoverageResult coverage;  // on the fine grid
  std::optional<OptimizeResult> optimized;
  std::optional<double> given_rig_search_score;  // a given rig's score on the search grid
  std::optional<double> given_rig_score;         // and on the fine grid
  std::vector<std::string> files;                // written
  std::string summary;                           // the table printed by the command
};

PlanRunResult RunPlan(const PlanRunOptions& options);

// coverage.json: the rig, the options, the ball-height layer's figures at the top level, every
// layer and, after a search, its scores.
nlohmann::json CoverageJson(const PlanRunResult& result, const field::FieldModel& field,
                            const PlanRunOptions& options);

}  // namespace fv::plan
