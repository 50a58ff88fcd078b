#include "fieldvision/detect/lab.h"

#include <mutex>

#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"

namespace fv::detect {
namespace {

void BuildTablesOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
    const cv::Mat pixel(1, 1, CV_8UC3, cv::Scalar::all(0));
    cv::Mat lab;
    cv::cvtColor(pixel, lab, cv::COLOR_BGR2Lab);
  });
}

}  // namespace

void BgrToLab(const cv::Mat& bgr, cv::Mat* lab) {
  FV_REQUIRE(lab != nullptr, "BgrToLab: no output image");
  if (bgr.empty()) {
    lab->release();
    return;
  }
  FV_REQUIRE(bgr.type() == CV_8UC3, "BgrToLab: the image must be 8-bit BGR");
  BuildTablesOnce();
  cv::cvtColor(bgr, *lab, cv::COLOR_BGR2Lab);
}

std::future<void> PrepareBgrToLab() { return std::async(std::launch::async, BuildTablesOnce); }

}  // namespace fv::detect
