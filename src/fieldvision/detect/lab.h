// 8-bit CIELAB for the detectors, in OpenCV's 8-bit convention (cv::COLOR_BGR2Lab: L * 255 / 100,
// a + 128, b + 128; sRGB, D65 white). Computed here from the CIE 1976 definition with a 256-entry
// sRGB linearisation table: OpenCV's own 8-bit conversion first builds interpolation tables in
// software floating point, 0.11-0.16 s of CPU in every process that converts one pixel (a large
// part of a short job's start, and the job's camera threads waited for it); these values are
// within 3 levels of OpenCV's (their tables interpolate) and exact to the definition.
// Reference: CIE 15:2004 (CIELAB), IEC 61966-2-1 (sRGB).
#pragma once

#include <opencv2/core.hpp>

namespace fv::detect {

// `bgr`: 8-bit, 3 channels (may be empty: `lab` is then empty). `lab` may not be `bgr`.
void BgrToLab(const cv::Mat& bgr, cv::Mat* lab);

}  // namespace fv::detect
