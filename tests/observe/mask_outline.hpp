#pragma once
// The outer outline of a decoded mask, for the tests that check the ellipse fits against
// OpenCV on outline points (the library fits from the runs and never needs this).

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "ellreloc/core/mask.hpp"

namespace ellreloc::test {

/// Points on the outer outline of a mask: the midpoints of the pixel edges between a mask
/// pixel and a background 4-neighbour connected to the outside (unbiased, unlike boundary pixel
/// centres; holes do not count). Edges on the image border are dropped (truncated objects),
/// and `touches_border` says whether there were any.
inline std::vector<Eigen::Vector2d> maskOutline(const BinaryMask& m, bool* touches_border = nullptr) {
  std::vector<Eigen::Vector2d> pts;
  if (touches_border) *touches_border = false;
  int x1 = m.width, y1 = m.height, x2 = -1, y2 = -1;
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x)
      if (m.at(x, y)) x1 = std::min(x1, x), x2 = std::max(x2, x), y1 = std::min(y1, y), y2 = std::max(y2, y);
  if (x2 < 0) return pts;
  // Background reachable from outside the bounding box (one-pixel frame), by flood fill.
  const int w = x2 - x1 + 3, h = y2 - y1 + 3;
  std::vector<uint8_t> outside(static_cast<size_t>(w) * h, 0);
  auto mask_at = [&](int fx, int fy) {  // frame coordinates
    const int x = fx + x1 - 1, y = fy + y1 - 1;
    return m.inside(x, y) && m.at(x, y);
  };
  std::vector<int> stack = {0};
  outside[0] = 1;
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    const int fx = i % w, fy = i / w;
    const int nx[4] = {fx + 1, fx - 1, fx, fx}, ny[4] = {fy, fy, fy + 1, fy - 1};
    for (int k = 0; k < 4; ++k) {
      if (nx[k] < 0 || ny[k] < 0 || nx[k] >= w || ny[k] >= h) continue;
      const int j = ny[k] * w + nx[k];
      if (!outside[j] && !mask_at(nx[k], ny[k])) outside[j] = 1, stack.push_back(j);
    }
  }
  static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
  for (int y = y1; y <= y2; ++y) {
    for (int x = x1; x <= x2; ++x) {
      if (!m.at(x, y)) continue;
      for (int k = 0; k < 4; ++k) {
        const int nx = x + dx[k], ny = y + dy[k];
        const int ix = nx + m.x0, iy = ny + m.y0;  // image coordinates of the neighbour
        if (ix < 0 || iy < 0 || ix >= m.image_width || iy >= m.image_height) {
          if (touches_border) *touches_border = true;
          continue;
        }
        if (outside[static_cast<size_t>(ny - y1 + 1) * w + (nx - x1 + 1)])
          pts.emplace_back(m.x0 + x + 0.5 * dx[k], m.y0 + y + 0.5 * dy[k]);
      }
    }
  }
  return pts;
}

}  // namespace ellreloc::test
