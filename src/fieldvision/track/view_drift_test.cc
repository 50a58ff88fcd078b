#include "fieldvision/track/view_drift.h"

#include <functional>
#include <iostream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::track {
namespace {

// The real PETS 2009 S2.L1 video (a still camera, people walking across most of the frame), its
// first 300 frames, those from frame 150 on changed by `change` (none: as they are).
ViewDriftStats DriftOfPets(const std::function<void(cv::Mat&)>& change = {}) {
  cv::VideoCapture video(fv::testing::SharedDataDir() + "/pets2009-s2l1/vtest.avi");
  EXPECT_TRUE(video.isOpened());
  ViewDrift drift;
  cv::Mat frame;
  for (int index = 0; index < 300 && video.read(frame); ++index) {
    if (index >= 150 && change) change(frame);
    drift.Add(index, frame, {});
  }
  return drift.stats();
}

// The still camera's view stays within 1 px of the first frame's (0.1 px over the whole video
// with its people's boxes left out: `players` on it); the same frames moved by 13 px from frame
// 150 on are found moved by that much (within 1 px), and frames that match nothing from there on
// count as moved.
TEST(ViewDrift, RealStillVideoStaysAndAKnockIsFound) {
  if (fv::testing::SharedDataDir().empty()) GTEST_SKIP() << "shared data absent";
  const ViewDriftStats still = DriftOfPets();
  std::cout << still.Summary() << "\n";
  EXPECT_EQ(still.checked, 29);
  EXPECT_LT(still.max_shift_px, 1.0);
  EXPECT_FALSE(still.moved);
  const ViewDriftStats knocked = DriftOfPets([](cv::Mat& frame) {
    cv::warpAffine(frame.clone(), frame, cv::Matx23d(1, 0, 12, 0, 1, -5), frame.size(),
                   cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  });
  std::cout << knocked.Summary() << "\n";
  EXPECT_TRUE(knocked.moved);
  EXPECT_NEAR(knocked.max_shift_px, 13.0, 1.0);
  EXPECT_GE(knocked.max_frame, 150);
  // Frames from 150 on that match nothing (flat here, the lens covered; a view turned away from
  // the first matches nothing either): over half the checks unmatched count as moved.
  const ViewDriftStats away =
      DriftOfPets([](cv::Mat& frame) { frame.setTo(cv::Scalar(90, 90, 90)); });
  std::cout << away.Summary() << "\n";
  EXPECT_GE(away.unmatched, 14);
  EXPECT_TRUE(away.moved);
}

TEST(ViewDrift, BadOptionsAreRefused) {
  ViewDriftOptions o;
  o.every_frames = 0;
  EXPECT_THROW(ViewDrift{o}, Error);
  o = {};
  o.moved_share = -1;
  EXPECT_THROW(ViewDrift{o}, Error);
}

}  // namespace
}  // namespace fv::track
