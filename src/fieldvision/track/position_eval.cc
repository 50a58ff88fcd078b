#include "fieldvision/track/position_eval.h"

#include <cmath>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "fieldvision/track/bytetrack.h"
#include "fieldvision/track/mot_internal.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace fv::track {

void PositionEvalOptions::Check() const {
  FV_REQUIRE(std::isfinite(iou_threshold) && iou_threshold > 0 && iou_threshold <= 1,
             "iou_threshold must be in (0, 1] (got {})", iou_threshold);
  FV_REQUIRE(std::isfinite(short_height_ratio) && short_height_ratio > 0 && short_height_ratio <= 1,
             "short_height_ratio must be in (0, 1] (got {})", short_height_ratio);
}

namespace {

// As EvaluateMot: MOT17 rules (conf 0 or not a pedestrian left out) where the file has classes.
bool Scored(const TrackRow& gt) { return gt.mot_class < 0 || (gt.conf > 0 && gt.mot_class == 1); }

bool HasPosition(const TrackRow& r) {
  return r.x_m && r.y_m && std::isfinite(*r.x_m) && std::isfinite(*r.y_m);
}

std::string Stats(const std::vector<double>& v) {
  if (v.empty()) return "none";
  return fmt::format("median {:.3f} m, mean {:.3f} m, p90 {:.3f} m, p99 {:.3f} m, max {:.3f} m",
                     util::Median(v), util::Mean(v), util::Percentile(v, 0.9),
                     util::Percentile(v, 0.99), util::Percentile(v, 1.0));
}

nlohmann::json StatsJson(const std::vector<double>& v) {
  if (v.empty()) return {{"rows", 0}};  // no numbers rather than zeros that read as perfect
  return {{"rows", v.size()},
          {"median_m", util::Median(v)},
          {"mean_m", util::Mean(v)},
          {"p90_m", util::Percentile(v, 0.9)},
          {"p99_m", util::Percentile(v, 0.99)},
          {"max_m", util::Percentile(v, 1.0)}};
}

}  // namespace

std::string PositionErrors::Summary() const {
  return fmt::format(
      "field positions: {} of {} annotated boxes matched, {} with a position on both sides: {}\n"
      "  {} rows whose box is short of the annotated one (legs hidden): {}",
      matched, gt_boxes, errors_m.size(), Stats(errors_m), short_errors_m.size(),
      Stats(short_errors_m));
}

std::string PositionErrors::ToJson() const {
  const nlohmann::json j = {{"gt_boxes", gt_boxes},
                            {"matched", matched},
                            {"without_position", without_position},
                            {"all", StatsJson(errors_m)},
                            {"short", StatsJson(short_errors_m)}};
  return j.dump(2);
}

void PlaceFeet(const camera::Camera& camera, double foot_offset_m, std::vector<TrackRow>* rows) {
  FV_REQUIRE(camera.has_pose, "camera '{}' has no pose: field positions need one", camera.name);
  FV_REQUIRE(std::isfinite(foot_offset_m), "foot offset must be finite (got {})", foot_offset_m);
  for (TrackRow& r : *rows) {
    if (HasPosition(r)) continue;
    const auto foot = FootOnGround(camera, r.box, foot_offset_m);
    if (!foot) continue;
    r.x_m = foot->x();
    r.y_m = foot->y();
  }
}

void PlaceFeet(const ViewCanvas& canvas, double foot_offset_m, std::vector<TrackRow>* rows) {
  std::vector<TrackRow> on_canvas;
  std::vector<size_t> index;
  for (size_t i = 0; i < rows->size(); ++i) {
    TrackRow r = (*rows)[i];
    if (HasPosition(r) || r.frame < 1 || r.frame > canvas.frames()) continue;
    r.box = canvas.BoxToCanvas(r.frame - 1, r.box);
    if (!BoxInRange(r.box)) continue;
    on_canvas.push_back(r);
    index.push_back(i);
  }
  PlaceFeet(canvas.camera(), foot_offset_m, &on_canvas);
  for (size_t k = 0; k < index.size(); ++k) {
    (*rows)[index[k]].x_m = on_canvas[k].x_m;
    (*rows)[index[k]].y_m = on_canvas[k].y_m;
  }
}

PositionErrors EvaluatePositions(const std::vector<TrackRow>& gt, const std::vector<TrackRow>& est,
                                 const PositionEvalOptions& options) {
  options.Check();
  std::map<int, std::vector<const TrackRow*>> gt_frames, est_frames;
  PositionErrors out;
  for (const TrackRow& r : gt) {
    if (!Scored(r)) continue;
    gt_frames[r.frame].push_back(&r);
    ++out.gt_boxes;
  }
  for (const TrackRow& r : est) est_frames[r.frame + options.frame_offset].push_back(&r);
  for (const auto& [frame, gs] : gt_frames) {
    const auto e = est_frames.find(frame);
    if (e == est_frames.end()) continue;
    for (const auto& [i, j] : MatchBoxes(gs, e->second, options.iou_threshold)) {
      const TrackRow& g = *gs[i];
      const TrackRow& s = *e->second[j];
      ++out.matched;
      if (!HasPosition(g) || !HasPosition(s)) {
        ++out.without_position;
        continue;
      }
      const double d = std::hypot(*s.x_m - *g.x_m, *s.y_m - *g.y_m);
      out.errors_m.push_back(d);
      if (s.box.height < options.short_height_ratio * g.box.height) {
        out.short_errors_m.push_back(d);
      }
    }
  }
  return out;
}

}  // namespace fv::track
