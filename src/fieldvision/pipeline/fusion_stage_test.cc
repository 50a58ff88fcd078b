// The fusion stage's predictor: a prior only from a track (two recent positions a plausible step
// apart), never from independent placements.
#include "fieldvision/pipeline/fusion_stage.h"

#include <gtest/gtest.h>

namespace fv::pipeline {
namespace {

using Eigen::Vector3d;

TEST(BallPredictor, PredictsAlongATrackOnly) {
  BallPredictor p(/*max_gap=*/5, /*max_step_m=*/1.5);
  EXPECT_FALSE(p.Predict(0).has_value());
  p.Add(10, Vector3d(0, 0, 0.11));
  EXPECT_FALSE(p.Predict(11).has_value());  // one position is no track
  p.Add(12, Vector3d(1, 0.5, 0.11));        // 0.56 m a frame
  const auto at14 = p.Predict(14);
  ASSERT_TRUE(at14.has_value());
  EXPECT_TRUE(at14->isApprox(Vector3d(2, 1, 0.11)));
  EXPECT_FALSE(p.Predict(18).has_value());  // the newest is more than 5 frames old
  EXPECT_FALSE(p.Predict(11).has_value());  // before the newest
  p.Add(13, Vector3d(6, -3, 0.11));         // a jump of 6 m in a frame: another object
  EXPECT_FALSE(p.Predict(14).has_value());
  p.Add(20, Vector3d(6.5, -3, 0.11));  // 7 frames after the last: too far apart
  EXPECT_FALSE(p.Predict(21).has_value());
  p.Add(21, Vector3d(6.6, -3, 0.11));
  ASSERT_TRUE(p.Predict(22).has_value());
  EXPECT_TRUE(p.Predict(22)->isApprox(Vector3d(6.7, -3, 0.11)));
}

}  // namespace
}  // namespace fv::pipeline
