#pragma once
// Convex polygons of image points, for the regular-mask test and the hull ellipse.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <queue>
#include <utility>
#include <vector>

#include "ellreloc/observe/regular_mask.hpp"

namespace ellreloc::polygon {

using Point = Eigen::Vector2d;

inline double cross(const Point& o, const Point& a, const Point& b) {
  return (a(0) - o(0)) * (b(1) - o(1)) - (a(1) - o(1)) * (b(0) - o(0));
}

inline double polygonArea(const std::vector<Point>& p) {
  double a = 0.0;
  for (size_t i = 0; i < p.size(); ++i) {
    const Point& u = p[i];
    const Point& v = p[(i + 1) % p.size()];
    a += u(0) * v(1) - u(1) * v(0);
  }
  return 0.5 * std::abs(a);
}

/// Reduces a convex polygon to `target` vertices by repeatedly dropping the vertex whose
/// removal loses the least area (Visvalingam-Whyatt; ties to the earliest vertex): a good
/// inscribed quadrilateral or triangle of the hull, whatever the object's thickness. A heap of
/// losses over a linked ring: O(n log n).
inline std::vector<Point> reduceTo(const std::vector<Point>& p, size_t target) {
  const size_t n = p.size();
  if (n <= target) return p;
  std::vector<size_t> prev(n), next(n);
  for (size_t i = 0; i < n; ++i) prev[i] = (i + n - 1) % n, next[i] = (i + 1) % n;
  std::vector<double> loss(n);
  std::vector<bool> alive(n, true);
  const auto lossOf = [&](size_t i) { return std::abs(cross(p[prev[i]], p[i], p[next[i]])); };
  using Entry = std::pair<double, size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  for (size_t i = 0; i < n; ++i) heap.push({loss[i] = lossOf(i), i});
  for (size_t remaining = n; remaining > target;) {
    const auto [l, i] = heap.top();
    heap.pop();
    if (!alive[i] || l != loss[i]) continue;  // removed, or its loss changed since
    alive[i] = false;
    --remaining;
    next[prev[i]] = next[i];
    prev[next[i]] = prev[i];
    for (const size_t j : {prev[i], next[i]}) heap.push({loss[j] = lossOf(j), j});
  }
  std::vector<Point> out;
  out.reserve(target);
  for (size_t i = 0; i < n; ++i)
    if (alive[i]) out.push_back(p[i]);
  return out;
}

/// Convex hull of a mask's pixel squares (Andrew's monotone chain), from its columns in
/// increasing x: only the extreme corners of each vertical grid line X = x - 1/2 matter, and
/// they come sorted by X. Clockwise on screen (y down); fewer than 3 points for no area.
inline std::vector<Point> hullOfColumns(const std::vector<MaskColumn>& cols) {
  std::vector<Point> top, bottom;  // per grid line: the highest and lowest corner
  for (size_t i = 0; i <= cols.size(); ++i) {
    // Grid line left of column i (and right of column i-1 when adjacent).
    const bool has_left = i > 0, has_right = i < cols.size();
    if (has_left && (!has_right || cols[i].x != cols[i - 1].x + 1)) {
      const MaskColumn& c = cols[i - 1];  // closing the previous column on its right side
      top.emplace_back(c.x + 0.5, c.ymin - 0.5);
      bottom.emplace_back(c.x + 0.5, c.ymax + 0.5);
    }
    if (has_right) {
      const MaskColumn& c = cols[i];
      double lo = c.ymin, hi = c.ymax;
      if (has_left && cols[i - 1].x == c.x - 1)
        lo = std::min<double>(lo, cols[i - 1].ymin), hi = std::max<double>(hi, cols[i - 1].ymax);
      top.emplace_back(c.x - 0.5, lo - 0.5);
      bottom.emplace_back(c.x - 0.5, hi + 0.5);
    }
  }
  // Image y points down: the upper chain keeps right turns on the top points, the lower chain
  // on the bottom points walked backwards; together a closed hull.
  std::vector<Point> hull;
  for (const Point& p : top) {
    while (hull.size() >= 2 && cross(hull[hull.size() - 2], hull.back(), p) <= 0) hull.pop_back();
    hull.push_back(p);
  }
  const size_t upper = hull.size() + 1;
  for (auto it = bottom.rbegin(); it != bottom.rend(); ++it) {
    while (hull.size() >= upper && cross(hull[hull.size() - 2], hull.back(), *it) <= 0) hull.pop_back();
    hull.push_back(*it);
  }
  while (hull.size() > 1 && (hull.back() - hull.front()).norm() < 1e-12) hull.pop_back();
  return hull;
}

/// The outline of a mask with every column filled between its extreme rows, through pixel
/// centres: each column's top row left to right, then its bottom row right to left (a closed
/// ring; the vertical sides of the first and last columns are its closing edges).
inline std::vector<Point> columnOutline(const std::vector<MaskColumn>& cols) {
  std::vector<Point> ring;
  ring.reserve(2 * cols.size());
  for (const MaskColumn& c : cols) ring.emplace_back(c.x, c.ymin);
  for (auto it = cols.rbegin(); it != cols.rend(); ++it) ring.emplace_back(it->x, it->ymax);
  return ring;
}

/// Douglas-Peucker on a closed ring, in the manner of cv::approxPolyDP for a closed curve:
/// split the ring at two far-apart points (the farthest from the first point, and the farthest
/// from that one), then keep, recursively, the point of each chain farthest from the line
/// through its ends while that distance exceeds `epsilon`, and finally drop the kept points
/// that lie close to the line through their neighbours. Returns the kept points in ring order.
inline std::vector<Point> douglasPeuckerRing(const std::vector<Point>& ring, double epsilon) {
  const size_t n = ring.size();
  if (n < 3) return ring;
  auto farthestFrom = [&](size_t from) {
    size_t best = from;
    double best_d = -1.0;
    for (size_t i = 0; i < n; ++i)
      if (const double d = (ring[i] - ring[from]).squaredNorm(); d > best_d) best_d = d, best = i;
    return best;
  };
  const size_t a = farthestFrom(0), b = farthestFrom(a);
  if (a == b) return {ring[a]};
  std::vector<bool> keep(n, false);
  keep[a] = keep[b] = true;
  // Chains as (first, last) ring indices walked forward; an explicit stack, no recursion.
  std::vector<std::pair<size_t, size_t>> stack = {{a, b}, {b, a}};
  while (!stack.empty()) {
    const auto [first, last] = stack.back();
    stack.pop_back();
    const Point& p = ring[first];
    const Point d = ring[last] - p;
    const double len = d.norm();
    size_t best = first;
    double best_dist = epsilon;
    for (size_t i = (first + 1) % n; i != last; i = (i + 1) % n) {
      const Point q = ring[i] - p;
      const double dist = len > 1e-12 ? std::abs(d(0) * q(1) - d(1) * q(0)) / len : q.norm();
      if (dist > best_dist) best_dist = dist, best = i;
    }
    if (best == first) continue;
    keep[best] = true;
    stack.push_back({first, best});
    stack.push_back({best, last});
  }
  std::vector<Point> out;
  for (size_t i = 0; i < n; ++i)
    if (keep[i]) out.push_back(ring[i]);
  // The two split points are kept whatever their place: one pass drops each kept point that
  // lies between its kept neighbours and within epsilon / sqrt(2) of the line through them (the
  // last step of cv::approxPolyDP for closed curves).
  for (size_t i = 0; i < out.size() && out.size() > 3;) {
    const Point& prev = out[(i + out.size() - 1) % out.size()];
    const Point& next = out[(i + 1) % out.size()];
    const Point d = next - prev, q = out[i] - prev;
    const double cross = d(0) * q(1) - d(1) * q(0);
    if (cross * cross <= 0.5 * epsilon * epsilon * d.squaredNorm() && q.dot(next - out[i]) >= 0)
      out.erase(out.begin() + static_cast<std::ptrdiff_t>(i));
    else
      ++i;
  }
  return out;
}

/// Length of a closed ring.
inline double ringLength(const std::vector<Point>& ring) {
  double length = 0.0;
  for (size_t i = 0; i < ring.size(); ++i) length += (ring[(i + 1) % ring.size()] - ring[i]).norm();
  return length;
}

/// True when every turn of the closed polygon goes the same way (collinear vertices allowed).
inline bool isConvexPolygon(const std::vector<Point>& p) {
  if (p.size() < 3) return false;
  int sign = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const double c = cross(p[i], p[(i + 1) % p.size()], p[(i + 2) % p.size()]);
    const int s = c > 0 ? 1 : c < 0 ? -1 : 0;
    if (s != 0 && sign != 0 && s != sign) return false;
    if (s != 0) sign = s;
  }
  return sign != 0;
}

}  // namespace ellreloc::polygon
