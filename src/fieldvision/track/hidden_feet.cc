#include "fieldvision/track/hidden_feet.h"

#include <algorithm>
#include <cmath>
#include <map>

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
// over its foot point (FootOnGround without offset): the person's height when the box is whole,
// less when the legs are hidden. Not finite when either ray misses.
double HeightOverFoot(const camera::Camera& camera, const cv::Rect2d& box) {
  const auto foot = FootOnGround(camera, box);
  const auto top = camera.RayFromPixel({box.x + 0.5 * box.width, box.y});
  if (!foot || !top) return std::nan("");
  const Eigen::Vector2d d = top->direction.head<2>();
  if (d.squaredNorm() < 1e-12) return std::nan("");
  const double s = (*foot - top->origin.head<2>()).dot(d) / d.squaredNorm();
  return s > 0 ? top->At(s).z() : std::nan("");
}

}  // namespace

int MendHiddenFeet(std::vector<TrackRow>& rows, const std::vector<bool>& measured,
                   const camera::Camera& camera, double foot_offset_m, double fps,
                   const HiddenFeetOptions& o, const FrameBoxOf& frame_box) {
  o.Check();
  FV_REQUIRE(measured.empty() || measured.size() == rows.size(),
             "MendHiddenFeet: {} measured flags for {} rows", measured.size(), rows.size());
  FV_REQUIRE(fps > 0, "MendHiddenFeet: fps must be positive (got {})", fps);
  if (!o.enabled || !camera.has_pose) return 0;
  // Per id: every row, and the measured ones (whose boxes give the person's height) by frame.
  std::map<int, std::vector<size_t>> all, by_id;
  std::vector<double> implied_m(rows.size());  // HeightOverFoot of each row
  for (size_t i = 0; i < rows.size(); ++i) {
    all[rows[i].id].push_back(i);
    if (measured.empty() || measured[i]) by_id[rows[i].id].push_back(i);
    implied_m[i] = HeightOverFoot(camera, rows[i].box);
  }
  const int half = std::max(1, static_cast<int>(std::lround(0.5 * o.window_s * fps)));
  std::vector<double> window, widths;
  int moved = 0;
  for (auto& [id, idx] : by_id) {
    std::sort(idx.begin(), idx.end(),
              [&](size_t a, size_t b) { return rows[a].frame < rows[b].frame; });
    std::vector<int> frames;
    for (const size_t k : idx) frames.push_back(rows[k].frame);
    for (const size_t i : all[id]) {
      const int f = rows[i].frame;
      const auto lo = std::lower_bound(frames.begin(), frames.end(), f - half) - frames.begin();
      const auto hi = std::upper_bound(frames.begin(), frames.end(), f + half) - frames.begin();
      window.clear();
      widths.clear();
      for (auto k = lo; k < hi; ++k) {
        if (std::isfinite(implied_m[idx[k]])) window.push_back(implied_m[idx[k]]);
        widths.push_back(rows[idx[k]].box.width);
      }
      if (window.size() < 3) continue;
      // The person's height is the same near or far: a window that reaches to one side only (a
      // track's end) serves as well as a centred one. Decisions read the boxes only, so a row
      // moved here changes none of the others.
      const double h_m = util::Median(window), w = util::Median(widths);
      const cv::Rect2d& box = rows[i].box;
      if (!(implied_m[i] < o.full_height_ratio * h_m) || box.width > o.max_width_ratio * w) {
        continue;
      }
      // The head may be above the image.
      if ((frame_box ? frame_box(rows[i]).y : box.y) <= o.top_edge_px) continue;
      // The foot below the box's top for a person h_m tall.
      if (const auto g =
              GroundBelowPixel(camera, {box.x + 0.5 * box.width, box.y}, h_m, foot_offset_m)) {
        rows[i].x_m = g->x();
        rows[i].y_m = g->y();
        ++moved;
      }
    }
  }
  return moved;
}

}  // namespace fv::track
