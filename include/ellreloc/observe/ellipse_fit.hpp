#pragma once
/// \file ellipse_fit.hpp
/// Ellipses from masks and points: the moment ellipse, the ellipse-specific direct
/// least-squares fit (Fitzgibbon, Pilu & Fisher 1999, in Halir & Flusser's numerically stable
/// form, 1998), the projectively inscribed ellipse of a quadrilateral, and the ellipse of a
/// silhouette's convex hull. Eigen only.

#include <Eigen/Dense>
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
inline std::optional<Ellipse> fitEllipseDirect(const std::vector<Eigen::Vector2d>& points) {
  const size_t n = points.size();
  if (n < 5) return std::nullopt;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(n);
  double spread = 0.0;
  for (const auto& p : points) spread += (p - mean).squaredNorm();
  const double scale = std::sqrt(spread / static_cast<double>(n));  // RMS distance to the mean
  if (!(scale > 0.0) || !std::isfinite(scale)) return std::nullopt;
  // The scatter matrices of D1 = [x^2, xy, y^2] and D2 = [x, y, 1] only need the 15 monomial
  // sums x^i y^j, i + j <= 4.
  double s40 = 0, s31 = 0, s22 = 0, s13 = 0, s04 = 0, s30 = 0, s21 = 0, s12 = 0, s03 = 0, s20 = 0, s11 = 0, s02 = 0,
         s10 = 0, s01 = 0;
  const double inv = 1.0 / scale;
  for (const auto& p : points) {
    const double x = (p(0) - mean(0)) * inv, y = (p(1) - mean(1)) * inv;
    const double xx = x * x, xy = x * y, yy = y * y;
    s40 += xx * xx, s31 += xx * xy, s22 += xx * yy, s13 += xy * yy, s04 += yy * yy;
    s30 += xx * x, s21 += xx * y, s12 += x * yy, s03 += yy * y;
    s20 += xx, s11 += xy, s02 += yy, s10 += x, s01 += y;
  }
  Eigen::Matrix3d S1, S2, S3;
  S1 << s40, s31, s22, s31, s22, s13, s22, s13, s04;
  S2 << s30, s21, s20, s21, s12, s11, s12, s03, s02;
  S3 << s20, s11, s10, s11, s02, s01, s10, s01, static_cast<double>(n);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(S3);
  if (!lu.isInvertible()) return std::nullopt;
  const Eigen::Matrix3d T = -lu.solve(S2.transpose());  // a2 = T a1
  const Eigen::Matrix3d M = S1 + S2 * T;
  // Premultiply by C1^-1 = [[0, 0, 1/2], [0, -1, 0], [1/2, 0, 0]].
  Eigen::Matrix3d Mc;
  Mc.row(0) = 0.5 * M.row(2);
  Mc.row(1) = -M.row(1);
  Mc.row(2) = 0.5 * M.row(0);
  const Eigen::EigenSolver<Eigen::Matrix3d> eig(Mc);
  if (eig.info() != Eigen::Success) return std::nullopt;
  // The ellipse is the eigenvector with 4ac - b^2 > 0 (exactly one for a proper fit).
  int best = -1;
  double best_cond = 0.0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d v = eig.eigenvectors().col(k).real();
    const double cond = 4.0 * v(0) * v(2) - v(1) * v(1);
    if (cond > best_cond) best = k, best_cond = cond;
  }
  if (best < 0) return std::nullopt;
  const Eigen::Vector3d a1 = eig.eigenvectors().col(best).real();
  const Eigen::Vector3d a2 = T * a1;
  // Conic in normalised coordinates; map back with q = (p - mean) / scale.
  Eigen::Matrix3d A;
  A << a1(0), a1(1) / 2, a2(0) / 2, a1(1) / 2, a1(2), a2(1) / 2, a2(0) / 2, a2(1) / 2, a2(2);
  Eigen::Matrix3d H;  // q = H p (homogeneous)
  H << 1.0 / scale, 0, -mean(0) / scale, 0, 1.0 / scale, -mean(1) / scale, 0, 0, 1;
  const Eigen::Matrix3d A_img = H.transpose() * A * H;
  const Eigen::FullPivLU<Eigen::Matrix3d> lu_a(A_img);
  if (!lu_a.isInvertible()) return std::nullopt;
  return Ellipse::fromDualConic(lu_a.inverse());
}

/// The image of the ellipse inscribed in the planar rectangle that a quadrilateral shows: the
/// ellipse tangent to the four sides at the images of their midpoints. It is the image of the
/// unit circle under the homography H taking the square [-1, 1]^2 to the quadrilateral (the
/// rectangle's own aspect ratio is an affine map, which keeps tangency at midpoints), so its
/// dual conic is H diag(1, 1, -1) H^T. The diagonals' intersection is the image of the centre,
/// and the vanishing points of opposite sides fix the midpoints' images. Corners in order
/// around the quadrilateral; nullopt for a non-convex or degenerate one.
inline std::optional<Ellipse> projectivelyInscribedEllipse(const std::array<Eigen::Vector2d, 4>& q) {
  const Eigen::Vector2d src[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  // DLT with h33 = 1: 8 equations.
  Eigen::Matrix<double, 8, 8> A;
  Eigen::Matrix<double, 8, 1> b;
  for (int i = 0; i < 4; ++i) {
    const double x = src[i](0), y = src[i](1), u = q[i](0), v = q[i](1);
    A.row(2 * i) << x, y, 1, 0, 0, 0, -u * x, -u * y;
    A.row(2 * i + 1) << 0, 0, 0, x, y, 1, -v * x, -v * y;
    b(2 * i) = u;
    b(2 * i + 1) = v;
  }
  const Eigen::FullPivLU<Eigen::Matrix<double, 8, 8>> lu(A);
  if (!lu.isInvertible()) return std::nullopt;
  const Eigen::Matrix<double, 8, 1> h = lu.solve(b);
  if (!h.allFinite()) return std::nullopt;
  Eigen::Matrix3d H;
  H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0;
  // The square must stay in front of the "camera" of H: w > 0 at all corners (convex image).
  for (const auto& s : src)
    if (!(H.row(2).dot(Eigen::Vector3d(s(0), s(1), 1.0)) > 0.0)) return std::nullopt;
  const Eigen::Matrix3d C = H * Eigen::Vector3d(1, 1, -1).asDiagonal() * H.transpose();
  return Ellipse::fromDualConic(C);
}

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
