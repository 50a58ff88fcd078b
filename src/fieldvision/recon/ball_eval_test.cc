#include "fieldvision/recon/ball_eval.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::recon {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(BallEval, MatchesByFrameAndSummarises) {
  testing::SeededRng rng(31);
  std::string truth = "frame,time_s,x_m,y_m,z_m,n_cams\n";
  std::string est = "frame,time_s,x_m,y_m,z_m,n_cams,err_px\n";
  std::vector<double> errs;
  for (int f = 0; f < 50; ++f) {
    const double x = rng.Uniform(-9, 9), y = rng.Uniform(-6, 6), z = rng.Uniform(0.11, 3);
    const int cams = f < 5 ? 1 : 3;
    truth += fmt::format("{},{},{},{},{},{}\n", f, f / 60.0, x, y, z, cams);
    if (f == 7 || f == 8) continue;                           // missed
    const double e = (f == 20) ? 0.8 : rng.Uniform(0, 0.01);  // one false estimate
    const double a = rng.Uniform(0, 2 * M_PI);
    est += fmt::format("{},{},{:.9f},{:.9f},{},3,0.5\n", f, f / 60.0, x + e * std::cos(a),
                       y + e * std::sin(a), z);
    errs.push_back(1000 * e);
  }
  est += "99,1.65,0,0,0,2,0.1\n";  // no truth for this frame
  const BallEvalResult r = EvaluateBall(util::CsvTable::Parse(truth, "truth.csv"),
                                        util::CsvTable::Parse(est, "ball.csv"));
  EXPECT_EQ(r.truth_frames, 50);
  EXPECT_EQ(r.visible_frames, 45);
  EXPECT_EQ(r.visible_found, 43);
  EXPECT_EQ(r.rows.size(), 48u);
  EXPECT_EQ(r.estimates_without_truth, 1);
  EXPECT_EQ(r.outliers, 1);
  double sum = 0;
  for (double e : errs) sum += e;
  EXPECT_NEAR(r.mean_mm, sum / errs.size(), 1e-3);
  std::sort(errs.begin(), errs.end());
  EXPECT_NEAR(r.max_mm, errs.back(), 1e-3);
  EXPECT_NEAR(r.median_mm, 0.5 * (errs[23] + errs[24]), 1e-3);
  EXPECT_LE(r.p95_mm, r.max_mm);
  EXPECT_GE(r.p95_mm, errs[44]);
  const std::string table = r.Table(true);
  EXPECT_NE(table.find("43 of 45"), std::string::npos) << table;
}

TEST(BallEval, BadFilesNameTheLine) {
  const util::CsvTable truth = util::CsvTable::Parse("frame,x_m,y_m,z_m\n0,1,2,3\n", "truth.csv");
  EXPECT_THAT(
      [&] {
        EvaluateBall(truth,
                     util::CsvTable::Parse("frame,x_m,y_m,z_m\n0,1,2,3\n0,1,2,3\n", "ball.csv"));
      },
      ThrowsMessage<Error>(HasSubstr("ball.csv:3")));
  EXPECT_THROW(
      EvaluateBall(truth, util::CsvTable::Parse("frame,x_m,y_m,z_m\n0,nan,2,3\n", "b.csv")), Error);
  EXPECT_THROW(EvaluateBall(truth, util::CsvTable::Parse("frame,x_m,y_m\n0,1,2\n", "b.csv")),
               Error);
  EXPECT_THROW(EvaluateBallFiles("/nonexistent/truth.csv", "/nonexistent/b.csv"), Error);
}

TEST(BallEval, NothingMatchedReportsNoError) {
  const BallEvalResult r =
      EvaluateBall(util::CsvTable::Parse("frame,x_m,y_m,z_m\n0,1,2,3\n1,1,2,3\n", "truth.csv"),
                   util::CsvTable::Parse("frame,x_m,y_m,z_m\n5,1,2,3\n", "ball.csv"));
  EXPECT_TRUE(r.rows.empty());
  const std::string table = r.Table(false);
  EXPECT_EQ(table.find("mean"), std::string::npos) << table;
  EXPECT_NE(table.find("error mm: none"), std::string::npos) << table;
}

}  // namespace
}  // namespace fv::recon
