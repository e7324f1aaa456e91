#pragma once
// Sequenced random draws for the simulator (internal).

#include <Eigen/Core>

namespace ellreloc::sim::detail {

/// N numbers from `draw`, the last coordinate drawn first. C++ leaves the order of function
/// arguments unspecified (GCC evaluates them right to left, Clang left to right), so draws are
/// sequenced here; right to left keeps the scenes generated before this helper existed.
template <int N, typename Draw>
Eigen::Matrix<double, N, 1> drawLastFirst(Draw&& draw) {
  Eigen::Matrix<double, N, 1> v;
  for (int i = N - 1; i >= 0; --i) v(i) = draw();
  return v;
}

}  // namespace ellreloc::sim::detail
