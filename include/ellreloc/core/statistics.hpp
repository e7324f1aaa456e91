#pragma once
/// \file statistics.hpp
/// Order statistics used across the library, its command line and its benchmarks.

#include <algorithm>
#include <vector>

namespace ellreloc {

/// The value of rank floor(q n) (0-based, clamped to n - 1) among n values: q = 0.5 gives the
/// median (the upper one of an even count), q = 0.9 the 90th percentile. `if_empty` when there
/// are no values.
inline double quantile(std::vector<double> values, double q, double if_empty = 0.0) {
  if (values.empty()) return if_empty;
  const double rank = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size());
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(rank));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(k), values.end());
  return values[k];
}

inline double median(std::vector<double> values, double if_empty = 0.0) {
  return quantile(std::move(values), 0.5, if_empty);
}

/// The q-quantile of values (0 <= q <= 1) with linear interpolation between order statistics
/// (position q (n - 1)), for extents that should move smoothly with the data. `if_empty` when
/// there are no values.
inline double interpolatedQuantile(std::vector<double> values, double q, double if_empty = 0.0) {
  if (values.empty()) return if_empty;
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(pos);
  std::nth_element(values.begin(), values.begin() + static_cast<long>(lo), values.end());
  const double a = values[lo];
  if (lo + 1 >= values.size()) return a;
  const double b = *std::min_element(values.begin() + static_cast<long>(lo) + 1, values.end());
  return a + (pos - static_cast<double>(lo)) * (b - a);
}

}  // namespace ellreloc
