#pragma once
/// \file regular_mask.hpp
/// Is a mask's outline roughly a convex quadrilateral (a "regular" object in the paper: a
/// monitor, a book, a keyboard seen as one face)? Two tests, both needed:
/// - the quadrilateral test: convex hull of the pixels -> reduction to the four corners that keep
///   the most area; the mask must fill that quadrilateral (overall, and in its core away from
///   the noisy boundary), three corners must not do as well (a triangle), and the corners must
///   be real corners. It tells whether the quadrilateral describes the mask, and so whether the
///   quadrilateral's ellipse suits it (a box seen with a sliver of a second face passes);
/// - the outline test, the paper's definition: the mask's outline reduced by Douglas-Peucker to
///   within 2% of its length is a convex quadrilateral (one face of a box, not two or three;
///   the simulator's truth applies it to the noise-free mask).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "ellreloc/core/mask.hpp"

namespace ellreloc {

/// Thresholds, chosen on the labelled set of tests/observe/test_regular_mask.cpp (rectangles,
/// perspective quadrilaterals and thin face-on boxes are regular; ellipses, triangles,
/// L-shapes, 2-3-face box silhouettes and blobs are not), with boundary noise.
struct RegularMaskOptions {
  double min_solidity = 0.75;  ///< mask area / hull area (noisy thin boxes reach 0.80)
  double min_fill = 0.85;      ///< mask area / quadrilateral area
  double max_fill = 1.15;
  double noise_band_px = 2.5;           ///< boundary noise expected on each side of the mask
  double min_core_fill = 0.95;          ///< share of the quadrilateral shrunk by noise_band_px covered by the mask
  double max_corner_angle_deg = 160.0;  ///< a corner flatter than this is no corner
  double min_corner_angle_deg = 20.0;
  int min_pixels = 30;  ///< smaller masks are never regular: too few pixels to tell
  /// Douglas-Peucker tolerance of the outline test, a share of the outline's length.
  double outline_tolerance = 0.02;
};

struct RegularVerdict {
  bool regular = false;        ///< both tests pass: the paper's regular object
  bool quadrilateral = false;  ///< the quadrilateral test passes: its ellipse describes the mask
  /// Vertices of the column outline reduced by Douglas-Peucker (outline test; 4 and convex to
  /// pass); 0 when the quadrilateral test failed, which spares the outline.
  int outline_vertices = 0;
  int hull_vertices = 0;       ///< vertices of the convex hull of the mask's pixel squares
  int quad_vertices = 0;       ///< vertices of the reduced hull: 4, or fewer for a tiny hull
  double solidity = 0.0;       ///< mask area / hull area
  double fill = 0.0;           ///< mask area / quadrilateral area (0 when there is no quadrilateral)
  double core_fill = 0.0;      ///< mask share of the quadrilateral shrunk by the noise band
  double triangle_fill = 0.0;  ///< mask area / area of the best 3-corner reduction (a triangle if in the fill range)
  double max_corner_angle_deg = 0.0;
  double min_corner_angle_deg = 0.0;
  std::array<Eigen::Vector2d, 4> corners{};  ///< around the quadrilateral, on the mask's outer pixel edges
  bool touches_border = false;               ///< the mask reaches the image border
  /// The convex hull of the mask's pixel squares (rleConvexHull), clockwise on screen; empty
  /// for a mask below min_pixels. The hull fit reuses it.
  std::vector<Eigen::Vector2d> hull;
};

/// Tests a run-length mask without decoding it: the convex hull of the pixel squares and the
/// outline come from each column's extreme rows, O(runs + columns); the outline test runs when
/// the quadrilateral test passes. An empty or inconsistent mask is not regular
/// (all diagnostics 0).
RegularVerdict testRegularMask(const RleMask& mask, const RegularMaskOptions& options = {});

/// The outline test: the outline of the mask with every column filled between its extreme rows
/// (through pixel centres, from the runs), reduced by Douglas-Peucker to within `tolerance` x
/// its length; returns its vertex count and sets `*convex` to whether that polygon is convex.
/// 0 for an empty or inconsistent mask. 4 and convex: the paper's regular object.
int outlineVertices(const RleMask& mask, double tolerance = 0.02, bool* convex = nullptr);

/// The rows a mask covers in one image column.
struct MaskColumn {
  int x = 0;
  int ymin = 0, ymax = 0;  ///< first and last row with a mask pixel
  int count = 0;           ///< mask pixels in the column
};

/// The non-empty columns of a run-length mask, in increasing x. Empty if inconsistent.
std::vector<MaskColumn> rleColumns(const RleMask& rle);

/// The convex hull of the mask's pixel squares, clockwise on screen (y down); fewer than 3
/// points for an empty or inconsistent mask. From the runs, no decoding.
std::vector<Eigen::Vector2d> rleConvexHull(const RleMask& rle);

/// Outline points of the mask with every column filled between its extreme rows (holes and
/// vertical notches closed): midpoints of the pixel edges on its boundary, image-border edges
/// dropped (`touches_border` says whether there were any). From the runs, no decoding.
std::vector<Eigen::Vector2d> rleOutline(const RleMask& rle, bool* touches_border = nullptr);

}  // namespace ellreloc
