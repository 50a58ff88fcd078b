// The part of a frame the detectors read for a search region: the region clipped to the frame,
// the whole frame when the region is empty (their shared contract: nothing outside it is read).
#pragma once

#include <opencv2/core/types.hpp>

namespace fv::detect {

inline cv::Rect SearchArea(const cv::Size& frame_size, const cv::Rect& region) {
  const cv::Rect frame(cv::Point(0, 0), frame_size);
  return region.empty() ? frame : (region & frame);
}

}  // namespace fv::detect
