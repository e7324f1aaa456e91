#include "ellreloc/io/time_index.hpp"

#include <algorithm>
#include <cmath>

namespace ellreloc::io {

TimeIndex::TimeIndex(const std::vector<double>& times) {
  by_time_.reserve(times.size());
  for (size_t k = 0; k < times.size(); ++k)
    if (std::isfinite(times[k])) by_time_.emplace_back(times[k], k);
  std::sort(by_time_.begin(), by_time_.end());
}

std::optional<size_t> TimeIndex::nearest(double t, double tolerance) const {
  if (!std::isfinite(t)) return std::nullopt;
  const auto earlier = [](const std::pair<double, size_t>& entry, double time) { return entry.first < time; };
  const auto later = [](double time, const std::pair<double, size_t>& entry) { return time < entry.first; };
  // The nearest times are the last before t and the first at or after it; of entries at one
  // time, the last position is the last of their run.
  const auto after = std::lower_bound(by_time_.begin(), by_time_.end(), t, earlier);
  std::optional<size_t> best;
  double best_dt = tolerance;
  const auto consider = [&](const std::pair<double, size_t>& entry) {
    const double dt = std::abs(entry.first - t);
    if (dt < best_dt || (dt == best_dt && (!best || entry.second > *best))) best = entry.second, best_dt = dt;
  };
  if (after != by_time_.begin()) consider(*std::prev(after));
  if (after != by_time_.end())
    consider(*std::prev(std::upper_bound(after, by_time_.end(), after->first, later)));
  return best;
}

}  // namespace ellreloc::io
