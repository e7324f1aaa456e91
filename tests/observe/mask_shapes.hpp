#pragma once
// Rasterised shapes for the observation tests: a pixel belongs to a shape when its centre does.

#include <random>
#include <vector>

#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/core/mask.hpp"

namespace ellreloc::test {

/// Point in a convex or concave polygon (even-odd rule).
inline bool inPolygon(const std::vector<Eigen::Vector2d>& poly, double x, double y) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const auto& a = poly[i];
    const auto& b = poly[j];
    if ((a(1) > y) != (b(1) > y) && x < (b(0) - a(0)) * (y - a(1)) / (b(1) - a(1)) + a(0)) in = !in;
  }
  return in;
}

inline BinaryMask rasterPolygon(const std::vector<Eigen::Vector2d>& poly, int w, int h) {
  BinaryMask m(h, w);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) m.at(x, y) = inPolygon(poly, x, y);
  return m;
}

inline BinaryMask rasterEllipse(const Ellipse& e, int w, int h) {
  BinaryMask m(h, w);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) m.at(x, y) = e.contains({double(x), double(y)});
  return m;
}

/// Boundary noise: each pixel with a 4-neighbour of the other value flips with probability p.
inline void addBoundaryNoise(BinaryMask& m, std::mt19937& rng, double p) {
  std::bernoulli_distribution flip(p);
  BinaryMask out = m;
  for (int y = 1; y + 1 < m.height; ++y)
    for (int x = 1; x + 1 < m.width; ++x) {
      const uint8_t v = m.at(x, y);
      const bool edge = m.at(x + 1, y) != v || m.at(x - 1, y) != v || m.at(x, y + 1) != v || m.at(x, y - 1) != v;
      if (edge && flip(rng)) out.at(x, y) = !v;
    }
  m = out;
}

}  // namespace ellreloc::test
