#pragma once
/// \file regular_mask.hpp
/// Is a mask's outline roughly a convex quadrilateral (a "regular" object in the paper: a
/// monitor, a book, a keyboard seen as one face)? Contour -> convex hull -> simplification to
/// four corners; then checks of how well the mask fills its hull and the quadrilateral, and of
/// the corners' angles.

#include <Eigen/Core>
#include <array>

#include "ellreloc/observe/mask.hpp"

namespace ellreloc {

/// Thresholds, chosen on the labelled set of tests/observe/test_regular_mask.cpp (rectangles,
/// perspective quadrilaterals and thin face-on boxes are regular; ellipses, triangles,
/// L-shapes, 2-3-face box silhouettes and blobs are not), with boundary noise.
struct RegularMaskOptions {
  /// Largest simplification tolerance, as a share of the hull's perimeter, at which the hull
  /// must reduce to four corners.
  double max_simplification = 0.04;
  double min_solidity = 0.80;  ///< mask area / hull area (noisy thin boxes reach 0.82)
  double min_fill = 0.88;      ///< mask area / quadrilateral area
  double max_fill = 1.12;
  double max_corner_angle_deg = 160.0;  ///< a corner flatter than this is no corner (triangles)
  double min_corner_angle_deg = 20.0;
  int min_pixels = 30;  ///< smaller masks are never regular: too few pixels to tell
};

struct RegularVerdict {
  bool regular = false;
  int hull_vertices = 0;  ///< vertices of the convex hull of the outer contour
  int quad_vertices = 0;  ///< vertices after simplification at max_simplification
  double solidity = 0.0;  ///< mask area / hull area
  double fill = 0.0;      ///< mask area / quadrilateral area (0 when there is no quadrilateral)
  double triangle_fill =
      0.0;  ///< mask area / area of the best 3-corner simplification (a triangle if in the fill range)
  double max_corner_angle_deg = 0.0;
  double min_corner_angle_deg = 0.0;
  std::array<Eigen::Vector2d, 4> corners{};  ///< in order around the quadrilateral, when quad_vertices == 4
  bool touches_border = false;               ///< the mask reaches the image border
};

/// Tests a mask. An empty mask is not regular (all diagnostics 0).
RegularVerdict testRegularMask(const BinaryMask& mask, const RegularMaskOptions& options = {});

}  // namespace ellreloc
