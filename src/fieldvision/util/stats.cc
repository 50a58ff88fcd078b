#include "fieldvision/util/stats.h"

#include <algorithm>
#include <cmath>

namespace fv::util {

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  q = std::clamp(q, 0.0, 1.0);
  const double pos = q * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, values.size() - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(lo), values.end());
  const double v_lo = values[lo];
  if (hi == lo) return v_lo;
  const double v_hi =
      *std::min_element(values.begin() + static_cast<std::ptrdiff_t>(lo) + 1, values.end());
  return v_lo + (pos - static_cast<double>(lo)) * (v_hi - v_lo);
}

double Median(std::vector<double> values) { return Percentile(std::move(values), 0.5); }

double NearestRankPercentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  q = std::clamp(q, 0.0, 1.0);
  const size_t k =
      std::min(values.size() - 1, static_cast<size_t>(std::floor(q * (values.size() - 1) + 0.5)));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

double NearestRankPercentile(const std::vector<int>& values, double q) {
  return NearestRankPercentile(std::vector<double>(values.begin(), values.end()), q);
}

double RankPercentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto rank = static_cast<size_t>(std::ceil(q * values.size()));
  const size_t k = std::min(values.size() - 1, rank == 0 ? 0 : rank - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

double Mean(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double s = 0.0;
  for (double v : values) s += v;
  return s / static_cast<double>(values.size());
}

double Rms(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double s = 0.0;
  for (double v : values) s += v * v;
  return std::sqrt(s / static_cast<double>(values.size()));
}

double RobustSigma(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  const double m = Median(values);
  std::vector<double> dev;
  dev.reserve(values.size());
  for (double v : values) dev.push_back(std::abs(v - m));
  return kMadToSigma * Median(std::move(dev));
}

double BicGain(double sse_without, double sse_with, long long num_residuals, int extra_params) {
  if (num_residuals <= extra_params || !(sse_with > 0) || !(sse_without > 0)) return -1e300;
  const double n = static_cast<double>(num_residuals);
  return n * std::log(sse_without / sse_with) - extra_params * std::log(n);
}

}  // namespace fv::util
