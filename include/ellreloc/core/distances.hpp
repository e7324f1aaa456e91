#pragma once
/// \file distances.hpp
/// Distances and overlaps between image ellipses. Formulas and their derivations are in
/// docs/distances.md. Invalid ellipses (see Ellipse::isValid) give +infinity for distances and
/// 0 for overlaps, never NaN.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

#include "ellreloc/core/ellipse.hpp"

namespace ellreloc {

/// Squared Wasserstein-2 distance between the Gaussians N(m1, S1) and N(m2, S2) in closed form
/// for 2x2 covariances, without a matrix square root:
///   W2^2 = |m1 - m2|^2 + tr S1 + tr S2 - 2 sqrt(tr(S1 S2) + 2 sqrt(det S1 det S2)).
/// The covariance part is evaluated as
///   (|S1 - S2|_F^2 + 2 det(S1 + S2) - 8 sqrt(det S1 det S2)) / (tr S1 + tr S2 + 2 s),
/// which is algebraically equal but has no cancellation for nearly equal ellipses and is
/// exactly 0 for equal ones. Templated for Ceres.
template <typename T>
T wasserstein2Squared(const Vec2<T>& m1, const Mat2<T>& S1, const Vec2<T>& m2, const Mat2<T>& S2) {
  using std::sqrt;
  const T det1 = S1(0, 0) * S1(1, 1) - S1(0, 1) * S1(1, 0);
  const T det2 = S2(0, 0) * S2(1, 1) - S2(0, 1) * S2(1, 0);
  const Mat2<T> sum = S1 + S2;
  const T det_sum = sum(0, 0) * sum(1, 1) - sum(0, 1) * sum(1, 0);
  const T tr_prod = S1(0, 0) * S2(0, 0) + S1(0, 1) * S2(1, 0) + S1(1, 0) * S2(0, 1) + S1(1, 1) * S2(1, 1);
  // Rounding can make the determinant of a very thin ellipse slightly negative: clamp.
  const T det_prod = det1 * det2;
  const T root_det = det_prod > T(0) ? sqrt(det_prod) : T(0);
  const T s2 = tr_prod + T(2) * root_det;
  const T s = s2 > T(0) ? sqrt(s2) : T(0);
  const T denom = S1(0, 0) + S1(1, 1) + S2(0, 0) + S2(1, 1) + T(2) * s;
  T numer = (S1 - S2).squaredNorm() + T(2) * det_sum - T(8) * root_det;
  if (numer < T(0)) numer = T(0);  // rounding only: the exact value is >= 0
  const T cov_term = denom > T(0) ? numer / denom : T(0);
  return (m1 - m2).squaredNorm() + cov_term;
}

/// Square root of a 2x2 symmetric positive definite matrix in closed form:
///   sqrt(S) = (S + sqrt(det S) I) / sqrt(tr S + 2 sqrt(det S)).
template <typename T>
Mat2<T> sqrtSpd2(const Mat2<T>& S) {
  using std::sqrt;
  const T det = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
  const T root_det = sqrt(det > T(0) ? det : T(0));
  const T denom = sqrt(S(0, 0) + S(1, 1) + T(2) * root_det);
  Mat2<T> R = S;
  R(0, 0) += root_det;
  R(1, 1) += root_det;
  return R / denom;
}

/// A 6-vector whose squared norm is W2^2, for least squares (so the solver minimises W2^2,
/// not W2^4). By the Procrustes form of the Bures distance,
///   tr S1 + tr S2 - 2 tr (S1^1/2 S2 S1^1/2)^1/2 = min over rotations U of |S1^1/2 - S2^1/2 U|_F^2,
/// and for 2x2 matrices the optimal U is the rotation by atan2(x01 - x10, x00 + x11) with
/// X = S1^1/2 S2^1/2 (tr X > 0 for positive definite S1, S2, so it is always defined). The
/// residual is [m1 - m2; vec(S1^1/2 - S2^1/2 U)]: smooth, no square root of W2 itself, and
/// so no infinite derivative at W2 = 0. Templated for Ceres Jets.
template <typename T>
void wasserstein2Residual(const Vec2<T>& m1, const Mat2<T>& S1, const Vec2<T>& m2, const Mat2<T>& S2, T* r) {
  using std::atan2;
  using std::cos;
  using std::sin;
  const Mat2<T> A = sqrtSpd2(S1), B = sqrtSpd2(S2);
  const Mat2<T> X = A * B;
  const T theta = atan2(X(0, 1) - X(1, 0), X(0, 0) + X(1, 1));
  const T c = cos(theta), s = sin(theta);
  Mat2<T> U;
  U << c, -s, s, c;
  const Mat2<T> D = A - B * U;
  r[0] = m1(0) - m2(0);
  r[1] = m1(1) - m2(1);
  r[2] = D(0, 0);
  r[3] = D(0, 1);
  r[4] = D(1, 0);
  r[5] = D(1, 1);
}

inline double wasserstein2Squared(const Ellipse& a, const Ellipse& b) {
  if (!a.isValid() || !b.isValid()) return std::numeric_limits<double>::infinity();
  const double d = wasserstein2Squared<double>(a.center(), a.covariance(), b.center(), b.covariance());
  return std::isnan(d) ? std::numeric_limits<double>::infinity() : d;  // overflow of absurd sizes: far apart
}

/// Wasserstein-2 distance in pixels.
inline double wasserstein2(const Ellipse& a, const Ellipse& b) { return std::sqrt(wasserstein2Squared(a, b)); }

/// Bhattacharyya distance between the ellipses' Gaussians:
///   1/8 d^T S^-1 d + 1/2 ln(det S / sqrt(det S1 det S2)),  S = (S1 + S2) / 2, d = m1 - m2.
inline double bhattacharyya(const Ellipse& a, const Ellipse& b) {
  if (!a.isValid() || !b.isValid()) return std::numeric_limits<double>::infinity();
  const Eigen::Matrix2d S = 0.5 * (a.covariance() + b.covariance());
  const Eigen::Vector2d d = a.center() - b.center();
  // det S1 = (a1 b1)^2 exactly, which avoids cancellation for thin ellipses.
  const double ln_det1 = 2.0 * std::log(a.axes()(0) * a.axes()(1));
  const double ln_det2 = 2.0 * std::log(b.axes()(0) * b.axes()(1));
  const double det = S.determinant();
  if (!(det > 0.0)) return std::numeric_limits<double>::infinity();
  const double result = 0.125 * d.dot(S.inverse() * d) + 0.5 * (std::log(det) - 0.5 * (ln_det1 + ln_det2));
  return std::isnan(result) ? std::numeric_limits<double>::infinity() : std::max(0.0, result);
}

namespace detail {

/// What ellipseIoU's polygon of n vertices needs: cos and sin of its angular step, the radius
/// factor k that gives it the ellipse's area, (n/2) sin(2 pi/n) k^2 = pi, and the length of its
/// edges on the unit circle, 2 sin(pi/n). Computed once for the vertex counts in use (32 and 128).
struct PolygonConstants {
  double cs, sn, k, chord;
};
inline PolygonConstants makePolygonConstants(int vertices) {
  const double step = 2.0 * M_PI / vertices;
  return {std::cos(step), std::sin(step), std::sqrt(M_PI / (0.5 * vertices * std::sin(step))),
          2.0 * std::sin(0.5 * step)};
}
inline PolygonConstants polygonConstants(int vertices) {
  static const PolygonConstants c32 = makePolygonConstants(32), c128 = makePolygonConstants(128);
  return vertices == 32 ? c32 : vertices == 128 ? c128 : makePolygonConstants(vertices);
}

/// Which ellipse ellipseIoU maps onto the unit disc (the larger, e1 on a tie) and which it
/// approximates by a polygon: the overlap bounds must make the same choice to bound it.
struct DiscAndPolygon {
  const Ellipse& disc;
  const Ellipse& polygon;
};
inline bool firstIsPolygon(double area1, double area2) { return area1 < area2; }
inline DiscAndPolygon discAndPolygon(const Ellipse& e1, const Ellipse& e2, double area1, double area2) {
  return firstIsPolygon(area1, area2) ? DiscAndPolygon{e2, e1} : DiscAndPolygon{e1, e2};
}

/// x' = diag(1/a, 1/b) R^T (x - c) maps `e` onto the unit disc: this is its linear part.
inline Eigen::Matrix2d toUnitDisc(const Ellipse& e) {
  return e.axes().cwiseInverse().asDiagonal() * e.rotation().transpose();
}

/// atan2(y, x) to 2e-8 radians (Abramowitz & Stegun 4.4.49 on [0, 1], octant reduction): about
/// 1.5 times cheaper than std::atan2, with an error far below the IoU polygon's own.
inline double fastAtan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double hi = std::max(ax, ay), lo = std::min(ax, ay);
  if (!(hi > 0.0)) return 0.0;
  const double t = lo / hi, t2 = t * t;
  double a = -0.0161657367 + t2 * 0.0028662257;
  a = 0.0429096138 + t2 * a;
  a = -0.0752896400 + t2 * a;
  a = 0.1065626393 + t2 * a;
  a = -0.1420889944 + t2 * a;
  a = 0.1999355085 + t2 * a;
  a = -0.3333314528 + t2 * a;
  a = t * (1.0 + t2 * a);
  if (ay > ax) a = 0.5 * M_PI - a;
  if (x < 0.0) a = M_PI - a;
  return y < 0.0 ? -a : a;
}

/// Whether the segment p-q stays outside the unit disc (touching it at most), so that
/// triangleDiscArea(p, q) is the circular sector it subtends.
inline bool segmentOutsideDisc(const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
  const double C = p.squaredNorm() - 1.0;
  if (!(C > 0.0) || !(q.squaredNorm() > 1.0)) return false;
  // Both ends are outside: |p + t d|^2 = 1 has its roots on one side of [0, 1], and the segment
  // enters the disc only when its point nearest the centre, t = -B / A, lies within and inside.
  const Eigen::Vector2d d = q - p;
  const double A = d.squaredNorm(), B = p.dot(d);
  return !(B < 0.0 && -B < A && B * B - A * C > 0.0);
}

/// Signed area of (triangle origin, p, q) intersected with the unit disc.
inline double triangleDiscArea(const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
  const double cross_pq = p(0) * q(1) - p(1) * q(0);
  if (p.squaredNorm() <= 1.0 && q.squaredNorm() <= 1.0) return 0.5 * cross_pq;  // disc is convex
  const Eigen::Vector2d d = q - p;
  // |p + t d|^2 = 1  ->  (d.d) t^2 + 2 (p.d) t + (p.p - 1) = 0
  const double A = d.squaredNorm(), B = p.dot(d), C = p.squaredNorm() - 1.0;
  double cuts[4] = {0.0, 0.0, 0.0, 1.0};
  int n = 1;
  const double disc = B * B - A * C;
  if (A > 0.0 && disc > 0.0) {
    const double r = std::sqrt(disc);
    const double t1 = (-B - r) / A, t2 = (-B + r) / A;
    if (t1 > 0.0 && t1 < 1.0) cuts[n++] = t1;
    if (t2 > 0.0 && t2 < 1.0) cuts[n++] = t2;
  }
  cuts[n++] = 1.0;
  double area = 0.0;
  for (int i = 0; i + 1 < n; ++i) {
    const Eigen::Vector2d a = p + cuts[i] * d, b = p + cuts[i + 1] * d;
    const Eigen::Vector2d mid = 0.5 * (a + b);
    const double cross = a(0) * b(1) - a(1) * b(0);
    if (mid.squaredNorm() <= 1.0)
      area += 0.5 * cross;  // piece inside the disc: a plain triangle
    else
      area += 0.5 * fastAtan2(cross, a.dot(b));  // outside: a circular sector
  }
  return area;
}

}  // namespace detail

/// Intersection over union of two ellipses.
///
/// IoU is invariant under affine maps, so the first ellipse is mapped to the unit disc and
/// the second, approximated by a polygon of `vertices` vertices whose area equals the
/// ellipse's, is intersected exactly with the disc (sum of signed triangle-disc areas).
/// The only approximation is that polygon: with the default 128 vertices the absolute IoU
/// error is below 1e-3 (tested against rasterisation). 0 for invalid input.
inline double ellipseIoU(const Ellipse& e1, const Ellipse& e2, int vertices = 128) {
  if (!e1.isValid() || !e2.isValid() || vertices < 3) return 0.0;
  const Box b1 = e1.boundingBox(), b2 = e2.boundingBox();
  if (b1.x2 <= b2.x1 || b2.x2 <= b1.x1 || b1.y2 <= b2.y1 || b2.y2 <= b1.y1) return 0.0;
  // Make the larger ellipse the disc: the polygon error then scales with the smaller area.
  const auto [big, small] = detail::discAndPolygon(e1, e2, e1.area(), e2.area());
  const Eigen::Matrix2d to_disc = detail::toUnitDisc(big);
  const Eigen::Matrix2d small_shape = small.rotation() * small.axes().asDiagonal();
  // Polygon radius scaled so its area is the ellipse's.
  const detail::PolygonConstants polygon = detail::polygonConstants(vertices);
  const Eigen::Vector2d offset = to_disc * (small.center() - big.center());
  const Eigen::Matrix2d shape = polygon.k * to_disc * small_shape;
  // Unit-circle points by repeated rotation: no sin/cos per vertex (drift ~1e-15 over n steps).
  const double cs = polygon.cs, sn = polygon.sn;
  Eigen::Vector2d unit(1.0, 0.0);
  const Eigen::Vector2d first = offset + shape * unit;
  Eigen::Vector2d prev = first;
  double inter_disc = 0.0;  // intersection area in the disc frame
  // Edges that stay outside the disc add circular sectors whose angles add up: a run of them
  // takes one atan2 of its ends instead of one per edge. An edge outside the unit disc
  // subtends at most its length, and every edge is at most |shape|_F 2 sin(pi / n) long, so a
  // run of max_run edges spans at most 3 radians: atan2 of its ends is its angle.
  const double edge_bound = shape.norm() * polygon.chord;
  const int max_run = edge_bound > 3.0 / vertices ? std::max(1, static_cast<int>(3.0 / edge_bound)) : vertices;
  Eigen::Vector2d run_start = first;
  int run = 0;
  const auto closeRun = [&](const Eigen::Vector2d& end) {
    inter_disc += 0.5 * detail::fastAtan2(run_start(0) * end(1) - run_start(1) * end(0), run_start.dot(end));
    run = 0;
  };
  for (int i = 1; i <= vertices; ++i) {
    unit = Eigen::Vector2d(cs * unit(0) - sn * unit(1), sn * unit(0) + cs * unit(1));
    const Eigen::Vector2d cur = i == vertices ? first : Eigen::Vector2d(offset + shape * unit);
    if (detail::segmentOutsideDisc(prev, cur)) {
      if (run == max_run) closeRun(prev);
      if (run == 0) run_start = prev;
      ++run;
    } else {
      if (run > 0) closeRun(prev);
      inter_disc += detail::triangleDiscArea(prev, cur);
    }
    prev = cur;
  }
  if (run > 0) closeRun(prev);
  // Both maps have a positive determinant, so the polygon stays counter-clockwise.
  const double inter = std::min(std::abs(inter_disc) * big.axes().prod(), small.area());
  const double uni = e1.area() + e2.area() - inter;
  return uni > 0.0 ? std::clamp(inter / uni, 0.0, 1.0) : 0.0;
}

namespace detail {

/// ellipseIoUUpperBound of two valid ellipses from their areas, centres and bounding boxes, for
/// callers that keep these.
inline double iouUpperBoundFromExtents(double area1, const Eigen::Vector2d& centre1, const Box& box1, double area2,
                                       const Eigen::Vector2d& centre2, const Box& box2, int vertices) {
  if (!std::isfinite(area1 + area2)) return 1.0;  // areas beyond a double: no bound
  const bool first_is_polygon = firstIsPolygon(area1, area2);
  const Box& s = first_is_polygon ? box1 : box2;
  const Box& b = first_is_polygon ? box2 : box1;
  const Eigen::Vector2d& c = first_is_polygon ? centre1 : centre2;
  const double k = polygonConstants(vertices).k;
  const double hx = 0.5 * k * s.width(), hy = 0.5 * k * s.height();
  const double w = std::min(c(0) + hx, b.x2) - std::max(c(0) - hx, b.x1);
  const double h = std::min(c(1) + hy, b.y2) - std::max(c(1) - hy, b.y1);
  if (!(w > 0.0) || !(h > 0.0)) return 0.0;
  const double inter = std::min(std::min(area1, area2), w * h);
  return inter / (area1 + area2 - inter);
}

}  // namespace detail

/// An upper bound of ellipseIoU(e1, e2, vertices) from the areas and the bounding boxes alone
/// (the smaller ellipse's box widened by the polygon's radius factor, as the polygon may reach
/// beyond the ellipse): a few operations instead of one atan2 per vertex, to skip pairs that
/// cannot reach a threshold.
inline double ellipseIoUUpperBound(const Ellipse& e1, const Ellipse& e2, int vertices = 128) {
  if (!e1.isValid() || !e2.isValid() || vertices < 3) return 0.0;
  return detail::iouUpperBoundFromExtents(e1.area(), e1.center(), e1.boundingBox(), e2.area(), e2.center(),
                                          e2.boundingBox(), vertices);
}

/// A lower bound of ellipseIoU(e1, e2, vertices), a few operations instead of one atan2 per
/// vertex, to accept pairs that certainly reach a threshold. In the frame where the larger
/// ellipse is the unit disc and the smaller's centre lies at radius rho < 1, the disc contains
/// the disc of radius 1 - rho around that centre, and the polygon contains the smaller ellipse
/// shrunk by k cos(pi/n) (semi-axes r1 >= r2): both contain the ellipse of semi-axes
/// min(r1, 1 - rho), min(r2, 1 - rho) around it.
inline double ellipseIoULowerBound(const Ellipse& e1, const Ellipse& e2, int vertices = 128) {
  if (!e1.isValid() || !e2.isValid() || vertices < 3) return 0.0;
  const double a1 = e1.area(), a2 = e2.area();
  if (!std::isfinite(a1 + a2)) return 0.0;  // areas beyond a double: no bound
  const auto [big, small] = detail::discAndPolygon(e1, e2, a1, a2);
  const Eigen::Matrix2d to_disc = detail::toUnitDisc(big);
  const double rho = (to_disc * (small.center() - big.center())).norm();
  if (!(rho < 1.0)) return 0.0;
  const detail::PolygonConstants polygon = detail::polygonConstants(vertices);
  const Eigen::Matrix2d M =
      polygon.k * std::cos(M_PI / vertices) * to_disc * small.rotation() * small.axes().asDiagonal();
  // Singular values of the 2x2 M from its Frobenius norm and determinant.
  const double f = M.squaredNorm(), d = std::abs(M.determinant());
  const double root = std::sqrt(std::max(0.0, f * f - 4.0 * d * d));
  const double r1 = std::sqrt(0.5 * (f + root)), r2 = d / std::max(r1, 1e-300);
  const double inter =
      std::min(M_PI * std::min(r1, 1.0 - rho) * std::min(r2, 1.0 - rho) * big.axes().prod(), small.area());
  if (!(inter > 0.0)) return 0.0;  // also 0 * inf at absurd scales: no bound then
  return inter / (a1 + a2 - inter);
}

/// Level-set distance between two ellipses, after Zins et al. (IROS 2022, "Level set-based
/// camera pose estimation from multiple 2D/3D ellipse-ellipsoid correspondences"): points are
/// sampled on the level sets rho_a = s (s in {1/2, 1, 3/2}) of each ellipse's Mahalanobis
/// radius rho, and compared with the other ellipse's radius at the same points:
///   d = sqrt( mean over both directions and all samples of (rho_b(x) - s)^2 ).
/// Dimensionless; 0 for equal ellipses (up to rounding); smooth in both ellipses' parameters.
/// `samples_per_level` points per level set and direction (default 16). Templated for Ceres.
template <typename T>
T levelSetDistance(const Vec2<T>& c1, const Mat2<T>& S1, const Vec2<T>& c2, const Mat2<T>& S2,
                   int samples_per_level = 16) {
  using std::sqrt;
  // Mahalanobis radius needs S^-1; the level-set points need a square root factor L with
  // L L^T = S (Cholesky of a 2x2 SPD matrix).
  auto inv = [](const Mat2<T>& S) {
    const T det = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
    Mat2<T> I;
    I << S(1, 1) / det, -S(0, 1) / det, -S(1, 0) / det, S(0, 0) / det;
    return I;
  };
  auto chol = [](const Mat2<T>& S) {
    Mat2<T> L = Mat2<T>::Zero();
    L(0, 0) = sqrt(S(0, 0));
    L(1, 0) = S(1, 0) / L(0, 0);
    L(1, 1) = sqrt(S(1, 1) - L(1, 0) * L(1, 0));
    return L;
  };
  const Mat2<T> L1 = chol(S1), L2 = chol(S2), I1 = inv(S1), I2 = inv(S2);
  const double levels[3] = {0.5, 1.0, 1.5};
  T sum = T(0);
  int count = 0;
  for (double s : levels) {
    for (int i = 0; i < samples_per_level; ++i) {
      const double t = 2.0 * M_PI * (i + 0.5) / samples_per_level;
      const Vec2<T> u(T(s * std::cos(t)), T(s * std::sin(t)));
      const Vec2<T> x1 = c1 + L1 * u;  // on level s of ellipse 1
      const Vec2<T> x2 = c2 + L2 * u;  // on level s of ellipse 2
      const Vec2<T> d1 = x1 - c2, d2 = x2 - c1;
      const T q1 = d1.dot(I2 * d1), q2 = d2.dot(I1 * d2);
      // sqrt(q) - s written as (q - s^2) / (sqrt(q) + s): no infinite derivative at q = 0.
      const T r1 = (q1 - T(s * s)) / (sqrt(q1 > T(0) ? q1 : T(0)) + T(s));
      const T r2 = (q2 - T(s * s)) / (sqrt(q2 > T(0) ? q2 : T(0)) + T(s));
      sum += r1 * r1 + r2 * r2;
      count += 2;
    }
  }
  return sqrt(sum / T(count));
}

inline double levelSetDistance(const Ellipse& a, const Ellipse& b, int samples_per_level = 16) {
  if (!a.isValid() || !b.isValid() || samples_per_level < 1) return std::numeric_limits<double>::infinity();
  const double d = levelSetDistance<double>(a.center(), a.covariance(), b.center(), b.covariance(), samples_per_level);
  return std::isnan(d) ? std::numeric_limits<double>::infinity() : d;
}

}  // namespace ellreloc
