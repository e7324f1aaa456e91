#pragma once
/// \file hungarian.hpp
/// Minimum-cost assignment (the Hungarian method, Kuhn 1955 / Munkres 1957) on a dense
/// rectangular cost matrix, in O(n^2 m) with row and column potentials and shortest augmenting
/// paths. Used by object tracking to associate map objects with a keyframe's detections.

#include <Eigen/Core>
#include <limits>
#include <vector>

namespace ellreloc {

/// Assigns each row of `cost` (rows x cols, finite entries) to a distinct column, or each
/// column to a distinct row when there are fewer columns, minimising the total cost. Returns
/// for every row the column it got, or -1 (only when rows > cols). Empty input: empty result.
inline std::vector<int> hungarianAssignment(const Eigen::MatrixXd& cost) {
  const bool transposed = cost.rows() > cost.cols();
  const Eigen::MatrixXd C = transposed ? Eigen::MatrixXd(cost.transpose()) : cost;
  const int n = static_cast<int>(C.rows()), m = static_cast<int>(C.cols());
  std::vector<int> row_of_col(static_cast<size_t>(m) + 1, 0);  // 1-based rows; 0 = free
  if (n == 0) return std::vector<int>(static_cast<size_t>(cost.rows()), -1);

  // Potentials u (rows) and v (columns) keep every reduced cost C(i,j) - u(i) - v(j) >= 0;
  // each row is added by a Dijkstra-like search for the cheapest augmenting path.
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(static_cast<size_t>(n) + 1, 0.0), v(static_cast<size_t>(m) + 1, 0.0);
  std::vector<int> way(static_cast<size_t>(m) + 1, 0);
  std::vector<double> min_to(static_cast<size_t>(m) + 1);
  std::vector<char> used(static_cast<size_t>(m) + 1);
  for (int i = 1; i <= n; ++i) {
    row_of_col[0] = i;
    int j0 = 0;
    std::fill(min_to.begin(), min_to.end(), inf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[j0] = 1;
      const int i0 = row_of_col[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double reduced = C(i0 - 1, j - 1) - u[i0] - v[j];
        if (reduced < min_to[j]) min_to[j] = reduced, way[j] = j0;
        if (min_to[j] < delta) delta = min_to[j], j1 = j;
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[row_of_col[j]] += delta;
          v[j] -= delta;
        } else {
          min_to[j] -= delta;
        }
      }
      j0 = j1;
    } while (row_of_col[j0] != 0);
    do {  // flip the augmenting path
      const int j1 = way[j0];
      row_of_col[j0] = row_of_col[j1];
      j0 = j1;
    } while (j0 != 0);
  }

  std::vector<int> result(static_cast<size_t>(cost.rows()), -1);
  for (int j = 1; j <= m; ++j) {
    if (row_of_col[j] == 0) continue;
    if (transposed)
      result[j - 1] = row_of_col[j] - 1;
    else
      result[row_of_col[j] - 1] = j - 1;
  }
  return result;
}

}  // namespace ellreloc
