#include "ellreloc/observe/regular_mask.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "polygon.hpp"

namespace ellreloc {

namespace {

using polygon::cross;
using polygon::Point;
using polygon::polygonArea;
using polygon::reduceTo;

/// The convex quadrilateral q moved inward by d on every side (intersections of the offset
/// sides); false when it vanishes.
bool shrinkQuad(const std::vector<Point>& q, double d, std::vector<Point>* out) {
  // Orientation: positive area means counter-clockwise in a y-up frame.
  double signed_area = 0.0;
  for (int i = 0; i < 4; ++i) signed_area += q[i](0) * q[(i + 1) % 4](1) - q[i](1) * q[(i + 1) % 4](0);
  const double side = signed_area > 0 ? 1.0 : -1.0;
  Point n[4], p[4];
  for (int i = 0; i < 4; ++i) {
    const Point e = (q[(i + 1) % 4] - q[i]).normalized();
    n[i] = side * Point(-e(1), e(0));  // inward normal
    p[i] = q[i] + d * n[i];
  }
  out->resize(4);
  for (int i = 0; i < 4; ++i) {
    // Intersect offset side i-1 (through p[i-1], direction q[i]-q[i-1]) with side i.
    const int j = (i + 3) % 4;
    const Point d1 = q[i] - q[j], d2 = q[(i + 1) % 4] - q[i];
    const double den = d1(0) * d2(1) - d1(1) * d2(0);
    if (std::abs(den) < 1e-12) return false;
    const Point w = p[i] - p[j];
    const double t = (w(0) * d2(1) - w(1) * d2(0)) / den;
    (*out)[i] = p[j] + t * d1;
  }
  // It vanished if the orientation flipped.
  double a = 0.0;
  for (int i = 0; i < 4; ++i) a += (*out)[i](0) * (*out)[(i + 1) % 4](1) - (*out)[i](1) * (*out)[(i + 1) % 4](0);
  return a * signed_area > 0 && std::abs(a) > 1.0;
}

/// Mask pixels whose centre lies inside the convex polygon q, counted from the runs.
long pixelsInside(const RleMask& rle, const std::vector<Point>& q) {
  long n = 0;
  forEachRunSegment(rle, [&](int x, int y0, int len) {
    // The polygon's vertical extent at this column.
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (size_t k = 0; k < q.size(); ++k) {
      const Point& a = q[k];
      const Point& b = q[(k + 1) % q.size()];
      if ((a(0) - x) * (b(0) - x) > 0 || a(0) == b(0)) continue;
      const double y = a(1) + (x - a(0)) / (b(0) - a(0)) * (b(1) - a(1));
      lo = std::min(lo, y), hi = std::max(hi, y);
    }
    if (lo <= hi) {
      const double first = std::max<double>(y0, std::ceil(lo)), last = std::min<double>(y0 + len - 1, std::floor(hi));
      if (last >= first) n += static_cast<long>(last - first + 1);
    }
  });
  return n;
}

/// The outline test on a mask's columns.
int outlineVerticesOf(const std::vector<MaskColumn>& cols, double tolerance, bool* convex) {
  if (convex) *convex = false;
  if (cols.empty()) return 0;
  const std::vector<Point> ring = polygon::columnOutline(cols);
  const std::vector<Point> reduced = polygon::douglasPeuckerRing(ring, tolerance * polygon::ringLength(ring));
  if (convex) *convex = polygon::isConvexPolygon(reduced);
  return static_cast<int>(reduced.size());
}

}  // namespace

std::vector<MaskColumn> rleColumns(const RleMask& rle) {
  std::vector<MaskColumn> cols;
  if (!rle.isConsistent()) return cols;
  cols.reserve(static_cast<size_t>(rle.width));
  forEachRunSegment(rle, [&cols](int x, int y0, int len) {
    if (cols.empty() || cols.back().x != x) cols.push_back({x, y0, y0 + len - 1, 0});
    MaskColumn& c = cols.back();
    c.ymin = std::min(c.ymin, y0);
    c.ymax = std::max(c.ymax, y0 + len - 1);
    c.count += len;
  });
  return cols;
}

RegularVerdict testRegularMask(const RleMask& rle, const RegularMaskOptions& options) {
  RegularVerdict v;
  const std::vector<MaskColumn> cols = rleColumns(rle);
  long area = 0;
  for (const MaskColumn& c : cols) area += c.count;
  if (area < options.min_pixels) return v;
  v.touches_border = cols.front().x == 0 || cols.back().x == rle.width - 1;
  for (const MaskColumn& c : cols) v.touches_border = v.touches_border || c.ymin == 0 || c.ymax == rle.height - 1;

  v.hull = polygon::hullOfColumns(cols);
  const std::vector<Point>& hull = v.hull;
  v.hull_vertices = static_cast<int>(hull.size());
  if (hull.size() < 3) return v;
  v.solidity = static_cast<double>(area) / polygonArea(hull);
  const std::vector<Point> quad = reduceTo(hull, 4);
  v.quad_vertices = static_cast<int>(quad.size());
  if (quad.size() != 4) return v;
  v.fill = static_cast<double>(area) / polygonArea(quad);
  // A triangle's hull also reduces to four corners (one cut off); it is a triangle when three
  // corners already enclose the mask as tightly as the regular range of fills allows.
  const std::vector<Point> tri = reduceTo(quad, 3);
  v.triangle_fill = static_cast<double>(area) / polygonArea(tri);
  v.min_corner_angle_deg = 180.0;
  for (int i = 0; i < 4; ++i) {
    const Point a = quad[(i + 3) % 4] - quad[i], b = quad[(i + 1) % 4] - quad[i];
    const double ang = std::acos(std::clamp(a.dot(b) / (a.norm() * b.norm() + 1e-12), -1.0, 1.0)) * 180.0 / M_PI;
    v.max_corner_angle_deg = std::max(v.max_corner_angle_deg, ang);
    v.min_corner_angle_deg = std::min(v.min_corner_angle_deg, ang);
    v.corners[i] = quad[i];  // hull vertices are pixel corners: on the mask's outer edge
  }
  // Core fill: the quadrilateral moved inward by the boundary noise band must be almost all
  // mask. Noise only nibbles at the edges; an L-shape or a notch leaves a hole in the core.
  std::vector<Point> core;
  v.core_fill = shrinkQuad(quad, options.noise_band_px, &core)
                    ? static_cast<double>(pixelsInside(rle, core)) / polygonArea(core)
                    : 1.0;  // too thin to have a core: judged by `fill` alone
  const bool triangle = v.triangle_fill >= options.min_fill && v.triangle_fill <= options.max_fill;
  v.quadrilateral = !triangle && v.core_fill >= options.min_core_fill && v.solidity >= options.min_solidity &&
                    v.fill >= options.min_fill && v.fill <= options.max_fill &&
                    v.max_corner_angle_deg <= options.max_corner_angle_deg &&
                    v.min_corner_angle_deg >= options.min_corner_angle_deg;
  if (!v.quadrilateral) return v;
  bool convex = false;
  v.outline_vertices = outlineVerticesOf(cols, options.outline_tolerance, &convex);
  v.regular = v.outline_vertices == 4 && convex;
  return v;
}

int outlineVertices(const RleMask& rle, double tolerance, bool* convex) {
  return outlineVerticesOf(rleColumns(rle), tolerance, convex);
}

std::vector<Eigen::Vector2d> rleConvexHull(const RleMask& rle) { return polygon::hullOfColumns(rleColumns(rle)); }

std::vector<Eigen::Vector2d> rleOutline(const RleMask& rle, bool* touches_border) {
  std::vector<Eigen::Vector2d> pts;
  const std::vector<MaskColumn> cols = rleColumns(rle);
  pts.reserve(4 * cols.size() + 64);
  bool border = false;
  const int W = rle.width, H = rle.height;
  for (size_t i = 0; i < cols.size(); ++i) {
    const MaskColumn& c = cols[i];
    // Top and bottom edges of the column, unless on the image border.
    if (c.ymin > 0)
      pts.emplace_back(c.x, c.ymin - 0.5);
    else
      border = true;
    if (c.ymax < H - 1)
      pts.emplace_back(c.x, c.ymax + 0.5);
    else
      border = true;
    // Vertical edges towards the left neighbour column (or empty space).
    const bool adjacent = i > 0 && cols[i - 1].x == c.x - 1;
    const double X = c.x - 0.5;
    if (c.x == 0) {
      border = true;
    } else if (!adjacent) {
      for (int y = c.ymin; y <= c.ymax; ++y) pts.emplace_back(X, y);
    } else {
      const MaskColumn& p = cols[i - 1];
      for (int y = c.ymin; y < p.ymin && y <= c.ymax; ++y) pts.emplace_back(X, y);          // c sticks out above p
      for (int y = std::max(c.ymin, p.ymax + 1); y <= c.ymax; ++y) pts.emplace_back(X, y);  // c sticks out below p
      for (int y = p.ymin; y < c.ymin && y <= p.ymax; ++y) pts.emplace_back(X, y);          // p sticks out above c
      for (int y = std::max(p.ymin, c.ymax + 1); y <= p.ymax; ++y) pts.emplace_back(X, y);  // p sticks out below c
    }
    // Right side of the last column of a group.
    const bool next_adjacent = i + 1 < cols.size() && cols[i + 1].x == c.x + 1;
    if (!next_adjacent) {
      if (c.x == W - 1)
        border = true;
      else
        for (int y = c.ymin; y <= c.ymax; ++y) pts.emplace_back(c.x + 0.5, y);
    }
  }
  if (touches_border) *touches_border = border;
  return pts;
}

}  // namespace ellreloc
