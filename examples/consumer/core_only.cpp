// ellreloc::core alone: Eigen and nothing else.
#include <ellreloc/core.hpp>

#include <cstdio>

int main() {
  const ellreloc::Ellipse a({0, 0}, {2, 1}, 0.0), b({0.5, 0}, {2, 1}, 0.0);
  const double w2 = ellreloc::wasserstein2(a, b);
  std::printf("core-only consumer ok: W2 = %.3f\n", w2);
  return std::abs(w2 - 0.5) < 1e-12 ? 0 : 1;
}
