// OpenCV's 8-bit CIELAB conversion (cv::COLOR_BGR2Lab: L * 255 / 100, a + 128, b + 128) for the
// detectors. OpenCV builds its conversion tables (about 0.1 s of CPU) on the first conversion,
// without a lock: threads converting at once would each build them, racing. Here the first call
// builds them under std::call_once, and a job can have them built on another thread while it opens
// its inputs and decodes its first frames, instead of before.
#pragma once

#include <future>

#include <opencv2/core.hpp>

namespace fv::detect {

// `bgr`: 8-bit, 3 channels (may be empty: `lab` is then empty).
void BgrToLab(const cv::Mat& bgr, cv::Mat* lab);

// Starts building the tables on another thread; conversions meanwhile wait for it. The future is
// ready when they are built (its destructor waits for that).
std::future<void> PrepareBgrToLab();

}  // namespace fv::detect
