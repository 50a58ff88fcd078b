#include "fieldvision/track/view_drift.h"

#include <fmt/format.h>

#include "fieldvision/util/error.h"

namespace fv::track {

void ViewDriftOptions::Check() const {
  FV_REQUIRE(every_frames >= 1, "ViewDriftOptions.every_frames must be >= 1 (got {})",
             every_frames);
  CheckPositive(moved_share, "ViewDriftOptions.moved_share");
}

std::string ViewDriftStats::Summary() const {
  if (checked == 0) return "view: not checked";
  // The frame of the largest move only where there was one (0.0 px at "frame 151" read oddly).
  return fmt::format(
      "view: {} frames registered to the first ({} matched to none), its centre moved up to "
      "{:.1f} px{}",
      checked, unmatched, max_shift_px,
      max_shift_px >= 0.05 ? fmt::format(" (frame {})", max_frame + 1) : "");
}

ViewDrift::ViewDrift(const ViewDriftOptions& options) : options_(options) { options_.Check(); }

void ViewDrift::Add(int index, const cv::Mat& bgr, const std::vector<cv::Rect2d>& people) {
  if (index > 0 && index % options_.every_frames != 0) return;
  const CameraMotionStats before = motion_.stats();
  motion_.Register(bgr, people);
  if (index == 0) {
    width_ = bgr.cols;
    return;
  }
  ++stats_.checked;
  const CameraMotionStats& after = motion_.stats();
  if (after.lost > before.lost) {
    ++stats_.unmatched;
    // Most checks matched to nothing: the view left the first one (or has too little texture
    // to tell).
    stats_.mostly_unmatched =
        stats_.mostly_unmatched || (stats_.checked >= 4 && 2 * stats_.unmatched > stats_.checked);
  } else if (after.max_shift_px > stats_.max_shift_px) {  // the registration's centre shift
    stats_.max_shift_px = after.max_shift_px;
    stats_.max_frame = index;
  }
  stats_.moved = stats_.mostly_unmatched || stats_.max_shift_px > options_.moved_share * width_;
}

}  // namespace fv::track
