#pragma once
/// \file time_index.hpp
/// The entry nearest in time, for many lookups: times sorted once, each lookup a binary search
/// instead of a pass over every entry.

#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

namespace ellreloc::io {

class TimeIndex {
 public:
  /// Indexes `times` by position; non-finite times are never found.
  explicit TimeIndex(const std::vector<double>& times);
  /// The position of the time nearest to t, if it is within `tolerance` seconds (by default
  /// 20 ms, as io::findNearest); of several equally near, the last position, as a pass over
  /// every entry that keeps the last of the nearest would find.
  std::optional<size_t> nearest(double t, double tolerance = 0.02) const;

 private:
  std::vector<std::pair<double, size_t>> by_time_;  // sorted by time, then position
};

}  // namespace ellreloc::io
