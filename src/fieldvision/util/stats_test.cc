#include "fieldvision/util/stats.h"

#include <gtest/gtest.h>

#include <random>

#include "fieldvision/util/testing.h"

namespace fv::util {
namespace {

TEST(Stats, PercentileInterpolatesLikeNumpy) {
  const std::vector<double> v = {4, 1, 3, 2, 5};
  EXPECT_DOUBLE_EQ(Percentile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Percentile(v, 1.0), 5.0);
  EXPECT_DOUBLE_EQ(Percentile(v, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(Percentile(v, 0.9), 4.6);  // numpy.percentile([1..5], 90)
  EXPECT_DOUBLE_EQ(Percentile({}, 0.5), 0.0);
  EXPECT_DOUBLE_EQ(Median({1, 2, 3, 10}), 2.5);
}

TEST(Stats, NearestRankPercentileIsASample) {
  const std::vector<double> v = {4, 1, 3, 2, 5, 6};
  EXPECT_DOUBLE_EQ(NearestRankPercentile(v, 0.5), 4.0);  // upper middle for an even n
  EXPECT_DOUBLE_EQ(NearestRankPercentile(std::vector<double>{4, 1, 3, 2, 5}, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(NearestRankPercentile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(NearestRankPercentile(v, 1.0), 6.0);
  EXPECT_DOUBLE_EQ(NearestRankPercentile(v, 0.95), 6.0);  // rank 4.75 -> 5
  EXPECT_DOUBLE_EQ(NearestRankPercentile(std::vector<double>{4, 1, 3, 2, 5}, 0.125),
                   2.0);  // rank 0.5 -> 1
  EXPECT_DOUBLE_EQ(NearestRankPercentile(std::vector<double>{4, 1, 3, 2, 5}, 0.375),
                   3.0);  // rank 1.5 -> 2
  EXPECT_DOUBLE_EQ(NearestRankPercentile(std::vector<int>{7, 9, 8}, 0.5), 8.0);
  EXPECT_DOUBLE_EQ(NearestRankPercentile(std::vector<double>{}, 0.5), 0.0);
}

TEST(Stats, RankPercentileIsTheSampleAtRankCeilQN) {
  const std::vector<double> v = {4, 1, 3, 2, 5, 6};
  EXPECT_DOUBLE_EQ(RankPercentile(v, 0.5), 3.0);  // rank 3: lower middle for an even n
  EXPECT_DOUBLE_EQ(RankPercentile(std::vector<double>{4, 1, 3, 2, 5}, 0.5), 3.0);  // rank 2.5 -> 3
  EXPECT_DOUBLE_EQ(RankPercentile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(RankPercentile(v, 1.0), 6.0);
  EXPECT_DOUBLE_EQ(RankPercentile(v, 0.8), 5.0);  // rank 4.8 -> 5
  EXPECT_DOUBLE_EQ(RankPercentile(std::vector<double>{}, 0.5), 0.0);
}

TEST(Stats, MeanRmsRobustSigma) {
  EXPECT_DOUBLE_EQ(Mean({1, 2, 3}), 2.0);
  EXPECT_DOUBLE_EQ(Rms({3, 4}), std::sqrt(12.5));
  const uint64_t seed = testing::TestSeed(7);
  FV_SEED_TRACE(seed);
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(10.0, 2.0);
  std::vector<double> v;
  v.reserve(21000);
  for (int i = 0; i < 20000; ++i) v.push_back(normal(rng));
  for (int i = 0; i < 1000; ++i) v.push_back(1e6);  // 5 % gross outliers
  EXPECT_NEAR(RobustSigma(v), 2.0, 0.3);            // outliers inflate it only a little
}

// Halving the sum of squares over 1000 residuals pays for one parameter by n ln 2 - ln n; a drop
// of 0.1 % does not; sums that are not positive give no gain.
TEST(Stats, BicGain) {
  EXPECT_NEAR(BicGain(100, 50, 1000, 1), 1000 * std::log(2.0) - std::log(1000.0), 1e-9);
  EXPECT_LT(BicGain(100, 99.9, 1000, 1), 0.0);
  EXPECT_NEAR(BicGain(100, 50, 1000, 2), 1000 * std::log(2.0) - 2 * std::log(1000.0), 1e-9);
  EXPECT_LT(BicGain(0, 50, 1000, 1), -1e299);
  EXPECT_LT(BicGain(100, 0, 1000, 1), -1e299);
  EXPECT_LT(BicGain(100, 50, 1, 1), -1e299);
}

}  // namespace
}  // namespace fv::util
