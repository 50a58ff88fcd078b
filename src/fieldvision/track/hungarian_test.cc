#include "fieldvision/track/hungarian.h"

#include <algorithm>
#include <numeric>

#include <gtest/gtest.h>

#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::track {
namespace {

// Brute force over all injective maps rows -> cols (rows <= cols), forbidden pairs skipped.
double BestCost(const std::vector<std::vector<double>>& c, double forbidden, int* best_count) {
  const int r = static_cast<int>(c.size()), n = static_cast<int>(c[0].size());
  std::vector<int> perm(n);
  std::iota(perm.begin(), perm.end(), 0);
  double best = 1e300;
  *best_count = -1;
  do {
    double s = 0;
    int count = 0;
    for (int i = 0; i < r; ++i) {
      if (c[i][perm[i]] < forbidden) {
        s += c[i][perm[i]];
        ++count;
      }
    }
    if (count > *best_count || (count == *best_count && s < best)) {
      best = s;
      *best_count = count;
    }
  } while (std::next_permutation(perm.begin(), perm.end()));
  return best;
}

TEST(Hungarian, MatchesBruteForceOnRandomMatrices) {
  fv::testing::SeededRng rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int rows = rng.UniformInt(1, 5), cols = rng.UniformInt(rows, 6);
    std::vector<std::vector<double>> c(rows, std::vector<double>(cols));
    for (auto& row : c) {
      for (auto& v : row) v = rng.Uniform() < 0.2 ? 1e9 : rng.Uniform(0, 10);
    }
    int best_count = 0;
    const double best = BestCost(c, 1e9, &best_count);
    const std::vector<int> a = SolveAssignment(c);
    ASSERT_EQ(static_cast<int>(a.size()), rows);
    double s = 0;
    int count = 0;
    std::vector<int> used;
    for (int i = 0; i < rows; ++i) {
      if (a[i] < 0) continue;
      ASSERT_LT(c[i][a[i]], 1e9) << "forbidden pair assigned";
      used.push_back(a[i]);
      s += c[i][a[i]];
      ++count;
    }
    std::sort(used.begin(), used.end());
    EXPECT_TRUE(std::adjacent_find(used.begin(), used.end()) == used.end());
    EXPECT_EQ(count, best_count) << "trial " << trial;
    EXPECT_NEAR(s, best, 1e-9) << "trial " << trial;
  }
}

TEST(Hungarian, MoreRowsThanColumnsAndEmpty) {
  EXPECT_TRUE(SolveAssignment({}).empty());
  const std::vector<int> a = SolveAssignment({{5.0}, {1.0}, {3.0}});
  EXPECT_EQ(a, (std::vector<int>{-1, 0, -1}));
}

}  // namespace
}  // namespace fv::track
