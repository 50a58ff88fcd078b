// Summary statistics used across modules (error tables, robust thresholds): percentiles with
// linear interpolation between closest ranks (numpy's default) or the nearest rank, median, mean,
// RMS, the median absolute deviation scaled to a normal sigma (Hampel 1974) and the Bayesian
// information criterion's gain of a model with more parameters (Schwarz 1978).
#pragma once

#include <vector>

namespace fv::util {

// q in [0, 1]; 0 for an empty sample. Non-finite values must be removed by the caller.
double Percentile(std::vector<double> values, double q);
double Median(std::vector<double> values);
// The sample at rank round(q (n - 1)) (no interpolation: always one of the values); for q = 0.5
// and an even n the upper of the two middle values. 0 for an empty sample.
double NearestRankPercentile(std::vector<double> values, double q);
double NearestRankPercentile(const std::vector<int>& values, double q);
// The sample at rank ceil(q n) counted from 1 (the textbook nearest rank): for q = 0.5 and an even
// n the lower of the two middle values. 0 for an empty sample.
double RankPercentile(std::vector<double> values, double q);
double Mean(const std::vector<double>& values);
double Rms(const std::vector<double>& values);
// Ratio of a normal distribution's sigma to its median absolute deviation.
inline constexpr double kMadToSigma = 1.4826;
// 1.4826 * median |x - median|: a normal sigma that ignores up to half the sample as outliers.
double RobustSigma(const std::vector<double>& values);
// How much the BIC drops when extra_params more parameters lower a least-squares fit's sum of
// squared residuals from sse_without to sse_with over num_residuals residuals (Gaussian noise):
// n ln(sse_without / sse_with) - extra_params ln n; > 0: they pay. -1e300 when either sum is
// not positive or n <= extra_params.
double BicGain(double sse_without, double sse_with, long long num_residuals, int extra_params);

}  // namespace fv::util
