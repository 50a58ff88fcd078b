#include "fieldvision/track/hidden_feet.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "fieldvision/geometry/rigid.h"
#include "fieldvision/track/bytetrack.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace fv::track {

void HiddenFeetOptions::Check() const {
  CheckInRange(full_height_ratio, 0.0, 1.0, "hidden feet full_height_ratio");
  CheckPositive(window_s, "hidden feet window_s");
  CheckInRange(max_width_ratio, 1.0, 10.0, "hidden feet max_width_ratio");
  CheckNonNegative(top_edge_px, "hidden feet top_edge_px");
}

namespace {

// The height above the ground (metres) at which the ray through the top centre of `box` passes
// over its foot point (the bottom centre on the ground): the person's height when the box is
// whole, less when the legs are hidden. Not finite when either ray misses.
double HeightOverFoot(const camera::Camera& camera, const cv::Rect2d& box) {
  const auto foot = camera.RayFromPixel({box.x + 0.5 * box.width, box.y + box.height});
  const auto top = camera.RayFromPixel({box.x + 0.5 * box.width, box.y});
  if (!foot || !top) return std::nan("");
  const auto g = geometry::IntersectHorizontalPlane(*foot, 0.0);
  const Eigen::Vector2d d = top->direction.head<2>();
  if (!g || d.squaredNorm() < 1e-12) return std::nan("");
  const double s = (g->head<2>() - top->origin.head<2>()).dot(d) / d.squaredNorm();
  return s > 0 ? top->At(s).z() : std::nan("");
}

// The foot below the top centre of `box` for a person `height_m` tall: where the top's ray is at
// that height, moved `offset_m` away from the camera (as FootOnGround).
std::optional<Eigen::Vector2d> FootBelowTop(const camera::Camera& camera, const cv::Rect2d& box,
                                            double height_m, double offset_m) {
  const auto top = camera.RayFromPixel({box.x + 0.5 * box.width, box.y});
  if (!top) return std::nullopt;
  const auto p = geometry::IntersectHorizontalPlane(*top, height_m);
  if (!p) return std::nullopt;
  Eigen::Vector2d g = p->head<2>();
  const Eigen::Vector2d away = g - camera.CentreInWorld().head<2>();
  if (offset_m != 0.0 && away.norm() > 1e-6) g += offset_m * away.normalized();
  return g;
}

}  // namespace

int MendHiddenFeet(std::vector<TrackRow>& rows, const std::vector<bool>& measured,
                   const camera::Camera& camera, double foot_offset_m, double fps,
                   const HiddenFeetOptions& o) {
  o.Check();
  FV_REQUIRE(measured.empty() || measured.size() == rows.size(),
             "MendHiddenFeet: {} measured flags for {} rows", measured.size(), rows.size());
  FV_REQUIRE(fps > 0, "MendHiddenFeet: fps must be positive (got {})", fps);
  if (!o.enabled || !camera.has_pose) return 0;
  // Per id: every row, and the measured ones (whose boxes give the person's height) by frame.
  std::map<int, std::vector<size_t>> all, by_id;
  for (size_t i = 0; i < rows.size(); ++i) {
    all[rows[i].id].push_back(i);
    if (measured.empty() || measured[i]) by_id[rows[i].id].push_back(i);
  }
  const int half = std::max(1, static_cast<int>(std::lround(0.5 * o.window_s * fps)));
  std::vector<std::pair<size_t, double>> mend;  // row, person's height: decided before moving
  std::vector<double> window, widths;
  for (auto& [id, idx] : by_id) {
    std::sort(idx.begin(), idx.end(),
              [&](size_t a, size_t b) { return rows[a].frame < rows[b].frame; });
    std::vector<int> frames;
    for (const size_t k : idx) frames.push_back(rows[k].frame);
    std::vector<double> heights_m(idx.size());  // HeightOverFoot of the measured rows
    for (size_t k = 0; k < idx.size(); ++k) heights_m[k] = HeightOverFoot(camera, rows[idx[k]].box);
    for (const size_t i : all[id]) {
      const int f = rows[i].frame;
      const auto lo = std::lower_bound(frames.begin(), frames.end(), f - half) - frames.begin();
      const auto hi = std::upper_bound(frames.begin(), frames.end(), f + half) - frames.begin();
      window.clear();
      widths.clear();
      for (auto k = lo; k < hi; ++k) {
        if (std::isfinite(heights_m[k])) window.push_back(heights_m[k]);
        widths.push_back(rows[idx[k]].box.width);
      }
      if (window.size() < 3) continue;
      // The person's height is the same near or far: a window that reaches to one side only (a
      // track's end) serves as well as a centred one.
      const double h_m = util::Median(window), w = util::Median(widths);
      const cv::Rect2d& box = rows[i].box;
      const double own = HeightOverFoot(camera, box);
      if (!(own < o.full_height_ratio * h_m) || box.width > o.max_width_ratio * w) continue;
      if (box.y <= o.top_edge_px) continue;  // the head may be above the image
      mend.emplace_back(i, h_m);
    }
  }
  int moved = 0;
  for (const auto& [i, height_m] : mend) {
    if (const auto g = FootBelowTop(camera, rows[i].box, height_m, foot_offset_m)) {
      rows[i].x_m = g->x();
      rows[i].y_m = g->y();
      ++moved;
    }
  }
  return moved;
}

}  // namespace fv::track
