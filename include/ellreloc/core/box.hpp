#pragma once
/// \file box.hpp
/// Axis-aligned image boxes [x1, y1, x2, y2] in pixels (docs/formats.md: pixel (0,0) is the
/// centre of the top-left pixel).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace ellreloc {

/// An axis-aligned box. Valid when all four numbers are finite and x1 <= x2, y1 <= y2.
struct Box {
  double x1 = 0, y1 = 0, x2 = 0, y2 = 0;

  Box() = default;
  Box(double x1_, double y1_, double x2_, double y2_) : x1(x1_), y1(y1_), x2(x2_), y2(y2_) {}

  double width() const { return x2 - x1; }
  double height() const { return y2 - y1; }
  double area() const { return isValid() ? width() * height() : 0.0; }
  Eigen::Vector2d center() const { return {0.5 * (x1 + x2), 0.5 * (y1 + y2)}; }

  bool isValid() const {
    return std::isfinite(x1) && std::isfinite(y1) && std::isfinite(x2) && std::isfinite(y2) && x1 <= x2 && y1 <= y2;
  }

  /// The overlap of two boxes; an empty box (zero width or height) when they are disjoint.
  Box intersection(const Box& o) const {
    Box r(std::max(x1, o.x1), std::max(y1, o.y1), std::min(x2, o.x2), std::min(y2, o.y2));
    if (r.x2 < r.x1) r.x2 = r.x1;
    if (r.y2 < r.y1) r.y2 = r.y1;
    return r;
  }

  /// Within `border_px` of the border of a width x height image (pixel centres at integers, so
  /// the image spans [-0.5, width - 0.5]): the object it bounds may be cut off by the border.
  bool nearImageBorder(int width, int height, double border_px) const {
    return x1 <= -0.5 + border_px || y1 <= -0.5 + border_px || x2 >= width - 0.5 - border_px ||
           y2 >= height - 0.5 - border_px;
  }
};

/// Intersection over union of two boxes, in [0, 1]; 0 when either box is invalid or empty.
inline double boxIoU(const Box& a, const Box& b) {
  if (!a.isValid() || !b.isValid()) return 0.0;
  const double inter = a.intersection(b).area();
  const double uni = a.area() + b.area() - inter;
  return uni > 0.0 ? inter / uni : 0.0;
}

}  // namespace ellreloc
