#include "fieldvision/track/hidden_feet.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "fieldvision/track/bytetrack.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace fv::track {
namespace {

// A box whose top is this near the image's top edge may have lost the head above it.
constexpr double kTopEdgePx = 2.0;

}  // namespace

void HiddenFeetOptions::Check() const {
  CheckInRange(full_height_ratio, 0.0, 1.0, "hidden feet full_height_ratio");
  CheckPositive(window_s, "hidden feet window_s");
  CheckInRange(max_width_ratio, 1.0, 10.0, "hidden feet max_width_ratio");
}

int MendHiddenFeet(std::vector<TrackRow>& rows, const std::vector<bool>& measured,
                   const camera::Camera& camera, double foot_offset_m, double fps,
                   const HiddenFeetOptions& o) {
  o.Check();
  FV_REQUIRE(measured.empty() || measured.size() == rows.size(),
             "MendHiddenFeet: {} measured flags for {} rows", measured.size(), rows.size());
  FV_REQUIRE(fps > 0, "MendHiddenFeet: fps must be positive (got {})", fps);
  if (!o.enabled || !camera.has_pose) return 0;
  std::map<int, std::vector<size_t>> by_id;  // measured rows of each id, by frame
  for (size_t i = 0; i < rows.size(); ++i) {
    if (measured.empty() || measured[i]) by_id[rows[i].id].push_back(i);
  }
  const int half = std::max(1, static_cast<int>(std::lround(0.5 * o.window_s * fps)));
  std::vector<std::pair<size_t, cv::Rect2d>> mend;  // decided on the boxes as found
  for (auto& entry : by_id) {
    std::vector<size_t>& idx = entry.second;
    std::sort(idx.begin(), idx.end(),
              [&](size_t a, size_t b) { return rows[a].frame < rows[b].frame; });
    size_t lo = 0, hi = 0;
    std::vector<double> heights, widths;
    for (const size_t i : idx) {
      const int f = rows[i].frame;
      while (rows[idx[lo]].frame < f - half) ++lo;
      while (hi < idx.size() && rows[idx[hi]].frame <= f + half) ++hi;
      heights.clear();
      widths.clear();
      for (size_t k = lo; k < hi; ++k) {
        heights.push_back(rows[idx[k]].box.height);
        widths.push_back(rows[idx[k]].box.width);
      }
      const double h = util::Median(heights), w = util::Median(widths);
      const cv::Rect2d& box = rows[i].box;
      if (box.height >= o.full_height_ratio * h || box.width > o.max_width_ratio * w) continue;
      if (box.y <= kTopEdgePx) continue;  // the head above the image: its top is not the head
      mend.emplace_back(i, cv::Rect2d(box.x, box.y, box.width, h));
    }
  }
  int moved = 0;
  for (const auto& [i, box] : mend) {
    if (const auto g = FootOnGround(camera, box, foot_offset_m)) {
      rows[i].x_m = g->x();
      rows[i].y_m = g->y();
      ++moved;
    }
  }
  return moved;
}

}  // namespace fv::track
