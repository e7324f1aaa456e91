#pragma once
/// \file ellipse_fit.hpp
/// Ellipses from masks and points: the moment ellipse, the ellipse-specific direct
/// least-squares fit (Fitzgibbon, Pilu & Fisher 1999, in Halir & Flusser's numerically stable
/// form, 1998), the projectively inscribed ellipse of a quadrilateral, and the ellipse of a
/// silhouette's convex hull. Eigen only; the fits are compiled (src/observe/ellipse_fit.cpp):
/// their eigen-solvers would cost every includer seconds of compilation.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/core/mask.hpp"

namespace ellreloc {

/// The ellipse with the same first and second moments as a region: a uniform ellipse of
/// semi-axes (a, b) has covariance R diag(a^2/4, b^2/4) R^T, so the ellipse is 2 sigma wide.
inline std::optional<Ellipse> momentEllipse(const MaskMoments& m) {
  if (!(m.area > 0.0)) return std::nullopt;
  return Ellipse::fromGaussian(m.mean, 4.0 * m.covariance);
}

/// Direct least-squares ellipse fit to points (Halir & Flusser's form of Fitzgibbon's
/// method): minimises the algebraic distance subject to 4ac - b^2 = 1, so the result is always
/// an ellipse when one exists. Points are centred and scaled first. nullopt for fewer than 5
/// points or degenerate sets (collinear points, NaN).
std::optional<Ellipse> fitEllipseDirect(const std::vector<Eigen::Vector2d>& points);

/// The image of the ellipse inscribed in the planar rectangle that a quadrilateral shows: the
/// ellipse tangent to the four sides at the images of their midpoints. It is the image of the
/// unit circle under the homography H taking the square [-1, 1]^2 to the quadrilateral (the
/// rectangle's own aspect ratio is an affine map, which keeps tangency at midpoints), so its
/// dual conic is H diag(1, 1, -1) H^T. The diagonals' intersection is the image of the centre,
/// and the vanishing points of opposite sides fix the midpoints' images. Corners in order
/// around the quadrilateral; nullopt for a non-convex or degenerate one.
std::optional<Ellipse> projectivelyInscribedEllipse(const std::array<Eigen::Vector2d, 4>& q);

/// The image of the ellipsoid inscribed in an object's cuboid, estimated from the convex hull of
/// its silhouette (rleConvexHull of its mask). Two shapes bound what the hull can be:
/// - a box: in parallel projection its silhouette is the zonotope sum_i a_i [-1, 1] of the
///   images a_i of its three half-edges, and its inscribed ellipsoid projects to the ellipse of
///   shape sum_i a_i a_i^T. The hull reduced to six corners, nearly parallel consecutive sides
///   merged, has the sides +-2 a_i, so that shape is the sum of s s^T / 8 over its sides s;
/// - an ellipsoid: the hull is its projection, the ellipse with 4x the hull's covariance.
/// The hull is weighed between the two by the share of its area that six corners keep: all of
/// a box's silhouette, 3 sqrt(3) / (2 pi) = 0.83 of an ellipse. A silhouette larger than the
/// cuboid's inscribed ellipsoid's projection (a box seen on its corner spans up to sqrt(3)
/// times it) thus gives an ellipse of that projection's size. nullopt for fewer than three
/// points or no area.
std::optional<Ellipse> hullEllipse(const std::vector<Eigen::Vector2d>& hull);

}  // namespace ellreloc
