#pragma once
/// \file p3p.hpp
/// Minimal absolute pose from three bearing-point correspondences, after Lambda Twist
/// (Persson & Nordberg, "Lambda Twist: An Accurate Fast Robust Perspective Three Point (P3P)
/// Solver", ECCV 2018). Header-only, Eigen only, no heap allocation.
///
/// With unit bearings y_i and world points x_i, the depths lambda_i satisfy
///   lambda_i^2 + lambda_j^2 + b_ij lambda_i lambda_j = a_ij,  b_ij = -2 y_i.y_j, a_ij = |x_i - x_j|^2.
/// Two homogeneous quadrics D1 = a23 M12 - a12 M23 and D2 = a23 M13 - a13 M23 vanish at the
/// solution; a root gamma of the cubic det(D1 + gamma D2) = 0 makes D0 = D1 + gamma D2 a pair of
/// planes through the origin, each giving lambda_1 linearly in (lambda_2, lambda_3); one
/// remaining quadratic gives lambda_2 / lambda_3. The depths are polished by Gauss-Newton on
/// the three original equations, and the pose follows from two difference vectors and their
/// cross product in both frames.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "ellreloc/core/camera.hpp"

namespace ellreloc {

namespace detail {

/// Newton polish of a root of x^3 + a x^2 + b x + c.
inline double polishCubicRoot(double a, double b, double c, double x) {
  for (int k = 0; k < 2; ++k) {
    const double f = ((x + a) * x + b) * x + c;
    const double df = (3.0 * x + 2.0 * a) * x + b;
    if (df != 0.0) x -= f / df;
  }
  return x;
}

/// Real roots of x^3 + a x^2 + b x + c in decreasing order, or only the largest when
/// `largest_only` (one acos and one cos instead of three); returns their count.
inline int solveMonicCubic(double a, double b, double c, double roots[3], bool largest_only) {
  const double Q = (a * a - 3.0 * b) / 9.0;
  const double R = (2.0 * a * a * a - 9.0 * a * b + 27.0 * c) / 54.0;
  if (R * R < Q * Q * Q) {  // three real roots: trigonometric form
    const double theta = std::acos(std::clamp(R / std::sqrt(Q * Q * Q), -1.0, 1.0));
    const double m = -2.0 * std::sqrt(Q);
    // cos((theta + 2 pi)/3) <= cos((theta - 2 pi)/3) <= cos(theta/3) and m < 0: largest first.
    roots[0] = polishCubicRoot(a, b, c, m * std::cos((theta + 2.0 * M_PI) / 3.0) - a / 3.0);
    if (largest_only) return 1;
    roots[1] = polishCubicRoot(a, b, c, m * std::cos((theta - 2.0 * M_PI) / 3.0) - a / 3.0);
    roots[2] = polishCubicRoot(a, b, c, m * std::cos(theta / 3.0) - a / 3.0);
    return 3;
  }
  double A = -std::cbrt(std::abs(R) + std::sqrt(R * R - Q * Q * Q));
  if (R < 0) A = -A;
  const double B = A != 0.0 ? Q / A : 0.0;
  roots[0] = polishCubicRoot(a, b, c, A + B - a / 3.0);
  return 1;
}

/// Splits a degenerate quadric lambda^T D lambda = 0 (symmetric, rank 2, indefinite) into its
/// two planes through the origin, D ~ l m^T + m l^T (Richter-Gebert, "Perspectives on
/// Projective Geometry", sec. 11.3): adj(D) = -p p^T with p = l x m, and D + [p]x = 2 m l^T has
/// rank one, so one of its rows is l and one of its columns m. False for a definite D (no
/// real planes).
inline bool splitPlanePair(const Eigen::Matrix3d& D, Eigen::Vector3d* l, Eigen::Vector3d* m) {
  // Diagonal of the adjugate: the principal 2x2 minors.
  const double b0 = D(1, 1) * D(2, 2) - D(1, 2) * D(2, 1);
  const double b1 = D(0, 0) * D(2, 2) - D(0, 2) * D(2, 0);
  const double b2 = D(0, 0) * D(1, 1) - D(0, 1) * D(1, 0);
  int i = 0;
  double bmin = b0;
  if (b1 < bmin) i = 1, bmin = b1;
  if (b2 < bmin) i = 2, bmin = b2;
  if (!(bmin < 0.0)) return false;
  const double beta = std::sqrt(-bmin);
  // Column i of the adjugate, divided by beta: p up to sign.
  Eigen::Vector3d p;
  const int j = (i + 1) % 3, k = (i + 2) % 3;
  p(i) = bmin;
  p(j) = D(k, i) * D(j, k) - D(j, i) * D(k, k);
  p(k) = D(j, i) * D(k, j) - D(k, i) * D(j, j);
  p /= beta;
  Eigen::Matrix3d A = D;
  A(0, 1) -= p(2), A(0, 2) += p(1), A(1, 0) += p(2), A(1, 2) -= p(0), A(2, 0) -= p(1), A(2, 1) += p(0);
  Eigen::Index r, c;
  A.cwiseAbs().maxCoeff(&r, &c);
  if (!(std::abs(A(r, c)) > 0.0)) return false;
  *l = A.row(r).transpose();
  *m = A.col(c);
  return true;
}

}  // namespace detail

namespace detail {

/// Gauss-Newton on the three original equations |lambda_i y_i - lambda_j y_j|^2 = a_ij
/// (b_ij = -2 y_i . y_j), from the depths the elimination gave.
inline void polishDepths(double a12, double a13, double a23, double b12, double b13, double b23,
                         Eigen::Vector3d* depths) {
  Eigen::Vector3d& lam = *depths;
  for (int it = 0; it < 5; ++it) {
    const Eigen::Vector3d res(lam(0) * lam(0) + lam(1) * lam(1) + b12 * lam(0) * lam(1) - a12,
                              lam(0) * lam(0) + lam(2) * lam(2) + b13 * lam(0) * lam(2) - a13,
                              lam(1) * lam(1) + lam(2) * lam(2) + b23 * lam(1) * lam(2) - a23);
    if (res.cwiseAbs().maxCoeff() < 1e-15 * (a12 + a13 + a23)) break;
    Eigen::Matrix3d J;
    J << 2 * lam(0) + b12 * lam(1), 2 * lam(1) + b12 * lam(0), 0.0, 2 * lam(0) + b13 * lam(2), 0.0,
        2 * lam(2) + b13 * lam(0), 0.0, 2 * lam(1) + b23 * lam(2), 2 * lam(2) + b23 * lam(1);
    const double detJ = J.determinant();
    if (!(std::abs(detJ) > 1e-300)) break;
    lam -= J.inverse() * res;
  }
}

}  // namespace detail

/// Solves P3P for unit bearing vectors (camera frame) and world points. Writes up to four
/// world->camera poses with all three depths positive into `poses` and returns their count.
/// Never produces NaN: degenerate input (coincident or collinear points, parallel bearings)
/// returns fewer or no solutions.
inline int p3p(const std::array<Eigen::Vector3d, 3>& bearings, const std::array<Eigen::Vector3d, 3>& points,
               std::array<Pose, 4>* poses) {
  const Eigen::Vector3d& y1 = bearings[0];
  const Eigen::Vector3d& y2 = bearings[1];
  const Eigen::Vector3d& y3 = bearings[2];
  const Eigen::Vector3d d12 = points[0] - points[1], d13 = points[0] - points[2];
  const double a12 = d12.squaredNorm(), a13 = d13.squaredNorm(), a23 = (points[1] - points[2]).squaredNorm();
  const double b12 = -2.0 * y1.dot(y2), b13 = -2.0 * y1.dot(y3), b23 = -2.0 * y2.dot(y3);

  // World triad: the inverse is shared by all solutions. Collinear points have none.
  Eigen::Matrix3d Xw;
  Xw << d12, d13, d12.cross(d13);
  const double det_w = Xw.determinant();
  const double a_max = std::max({a12, a13, a23});
  if (!(std::abs(det_w) > 1e-12 * a_max * a_max) || !std::isfinite(det_w)) return 0;
  const Eigen::Matrix3d Xw_inv = Xw.inverse();

  // D1 = a23 M12 - a12 M23, D2 = a23 M13 - a13 M23 (M_ij: the quadric of equation ij).
  Eigen::Matrix3d D1, D2;
  D1 << a23, 0.5 * b12 * a23, 0.0, 0.5 * b12 * a23, a23 - a12, -0.5 * b23 * a12, 0.0, -0.5 * b23 * a12, -a12;
  D2 << a23, 0.0, 0.5 * b13 * a23, 0.0, -a13, -0.5 * b23 * a13, 0.5 * b13 * a23, -0.5 * b23 * a13, a23 - a13;

  // det(D1 + g D2) = c3 g^3 + c2 g^2 + c1 g + c0, by multilinearity in the columns.
  auto det3 = [](const Eigen::Vector3d& u, const Eigen::Vector3d& v, const Eigen::Vector3d& w) {
    return u.dot(v.cross(w));
  };
  const Eigen::Vector3d p0 = D1.col(0), p1 = D1.col(1), p2 = D1.col(2);
  const Eigen::Vector3d q0 = D2.col(0), q1 = D2.col(1), q2 = D2.col(2);
  const double c3 = det3(q0, q1, q2);
  const double c2 = det3(p0, q1, q2) + det3(q0, p1, q2) + det3(q0, q1, p2);
  const double c1 = det3(q0, p1, p2) + det3(p0, q1, p2) + det3(p0, p1, q2);
  const double c0 = det3(p0, p1, p2);

  const double c_scale = std::max({std::abs(c0), std::abs(c1), std::abs(c2), std::abs(c3)});
  if (!(c_scale > 0.0) || !std::isfinite(c_scale)) return 0;
  const bool d2_degenerate = std::abs(c3) <= 1e-14 * c_scale;  // then gamma = infinity: D0 = D2
  int count = 0;
  double gammas[3];
  int n_gamma = 0;
  // Try the largest root of the cubic first; the others only if it does not factor into
  // real planes (rare), so the common case costs one acos and one cos.
  for (int pass = 0; pass < 2 && count == 0; ++pass) {
    if (d2_degenerate) {
      if (pass == 1) break;
      gammas[0] = std::numeric_limits<double>::infinity();
      n_gamma = 1;
    } else {
      n_gamma = detail::solveMonicCubic(c2 / c3, c1 / c3, c0 / c3, gammas, pass == 0);
      if (pass == 1 && n_gamma == 1) break;  // nothing new to try
    }
    for (int g = pass; g < n_gamma && count == 0; ++g) {
      const Eigen::Matrix3d D0 = std::isinf(gammas[g]) ? D2 : Eigen::Matrix3d(D1 + gammas[g] * D2);
      Eigen::Vector3d planes[2];
      if (!detail::splitPlanePair(D0, &planes[0], &planes[1])) continue;
      // On the planes of D0, D1 = -gamma D2: use the larger of the two as the remaining quadric.
      const Eigen::Matrix3d& Dq = std::abs(gammas[g]) > 1.0 ? D1 : D2;
      for (const Eigen::Vector3d& n : planes) {  // plane normal: n . lambda = 0
        if (!(std::abs(n(0)) > 1e-10 * n.norm())) continue;
        const double w0 = -n(1) / n(0), w1 = -n(2) / n(0);
        // lambda = lambda3 (w0 tau + w1, tau, 1) = lambda3 (p tau + r)
        const Eigen::Vector3d p(w0, 1.0, 0.0), r(w1, 0.0, 1.0);
        const double qa = p.dot(Dq * p), qb = 2.0 * p.dot(Dq * r), qc = r.dot(Dq * r);
        double taus[2];
        int n_tau = 0;
        if (std::abs(qa) > 1e-14 * (std::abs(qb) + std::abs(qc))) {
          const double disc = qb * qb - 4.0 * qa * qc;
          if (disc < 0.0) continue;
          const double root = std::sqrt(disc);
          // Numerically stable pair of roots.
          const double t = -0.5 * (qb + (qb >= 0 ? root : -root));
          taus[n_tau++] = t / qa;
          if (t != 0.0) taus[n_tau++] = qc / t;
        } else if (qb != 0.0) {
          taus[n_tau++] = -qc / qb;
        }
        for (int k = 0; k < n_tau && count < 4; ++k) {
          const double tau = taus[k];
          if (!(tau > 0.0)) continue;
          const double denom = tau * tau + b23 * tau + 1.0;
          if (!(denom > 0.0)) continue;
          Eigen::Vector3d lam;
          lam(2) = std::sqrt(a23 / denom);
          lam(1) = tau * lam(2);
          lam(0) = (w0 * tau + w1) * lam(2);
          if (!(lam(0) > 0.0)) continue;
          detail::polishDepths(a12, a13, a23, b12, b13, b23, &lam);
          if (!(lam.minCoeff() > 0.0) || !lam.allFinite()) continue;
          const Eigen::Vector3d c12 = lam(0) * y1 - lam(1) * y2, c13 = lam(0) * y1 - lam(2) * y3;
          Eigen::Matrix3d Yc;
          Yc << c12, c13, c12.cross(c13);
          const Eigen::Matrix3d R = Yc * Xw_inv;
          const Eigen::Vector3d t = lam(0) * y1 - R * points[0];
          if (!R.allFinite() || !t.allFinite()) continue;
          (*poses)[count++] = Pose(R, t);
        }
      }
    }
  }
  return count;
}

}  // namespace ellreloc
