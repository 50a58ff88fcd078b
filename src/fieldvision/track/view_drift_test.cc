#include "fieldvision/track/view_drift.h"

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
// first 300 frames as they are, or moved by (dx, dy) px from frame `from` on (a camera knocked).
ViewDriftStats DriftOfPets(double dx, double dy, int from) {
  cv::VideoCapture video(fv::testing::SharedDataDir() + "/pets2009-s2l1/vtest.avi");
  EXPECT_TRUE(video.isOpened());
  ViewDrift drift;
  cv::Mat frame;
  for (int index = 0; index < 300 && video.read(frame); ++index) {
    if (index >= from) {
      const cv::Matx23d shift(1, 0, dx, 0, 1, dy);
      cv::warpAffine(frame.clone(), frame, shift, frame.size(), cv::INTER_LINEAR,
                     cv::BORDER_REPLICATE);
    }
    drift.Add(index, frame, {});
  }
  return drift.stats();
}

// The still camera's view stays within 1 px of the first frame's (0.1 px over the whole video
// with its people's boxes left out: `players` on it); the same frames moved by 13 px from frame
// 150 on are found moved by that much (within 1 px).
TEST(ViewDrift, RealStillVideoStaysAndAKnockIsFound) {
  if (fv::testing::SharedDataDir().empty()) GTEST_SKIP() << "shared data absent";
  const ViewDriftStats still = DriftOfPets(0, 0, 300);
  std::cout << still.Summary() << "\n";
  EXPECT_EQ(still.checked, 29);
  EXPECT_LT(still.max_shift_px, 1.0);
  EXPECT_FALSE(still.moved);
  const ViewDriftStats knocked = DriftOfPets(12, -5, 150);
  std::cout << knocked.Summary() << "\n";
  EXPECT_TRUE(knocked.moved);
  EXPECT_NEAR(knocked.max_shift_px, 13.0, 1.0);
  EXPECT_GE(knocked.max_frame, 150);
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
