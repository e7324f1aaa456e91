#pragma once
/// \file ellipse.hpp
/// Image ellipses: parametric form (centre, semi-axes, angle), dual conic and Gaussian form.
///
/// Conventions (docs/conventions.md): `angle` is the direction of semi-axis a from the image
/// x axis, in radians. The Gaussian form has mean = centre and covariance
/// R(angle) diag(a^2, b^2) R(angle)^T. The dual conic is C* = H diag(a^2, b^2, -1) H^T with
/// H = [R c; 0 1], i.e. normalised so that C*(2,2) = -1.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "ellreloc/core/box.hpp"

namespace ellreloc {

template <typename T>
using Vec2 = Eigen::Matrix<T, 2, 1>;
template <typename T>
using Mat2 = Eigen::Matrix<T, 2, 2>;
template <typename T>
using Mat3 = Eigen::Matrix<T, 3, 3>;

/// Gaussian (mean, covariance) of an ellipse given by a dual conic of any scale and sign.
/// Templated so that Ceres can differentiate through it. Precondition: C(2,2) != 0.
template <typename T>
void gaussianFromDualConic(const Mat3<T>& C, Vec2<T>* mean, Mat2<T>* cov) {
  const T s = -C(2, 2);  // normalise to C*(2,2) = -1: then C*(0:2,2) = -centre
  const Vec2<T> m(C(0, 2) / -s, C(1, 2) / -s);
  Mat2<T> S;
  S(0, 0) = C(0, 0) / s + m(0) * m(0);
  S(1, 1) = C(1, 1) / s + m(1) * m(1);
  S(0, 1) = S(1, 0) = T(0.5) * (C(0, 1) + C(1, 0)) / s + m(0) * m(1);
  *mean = m;
  *cov = S;
}

/// Covariance R diag(a^2, b^2) R^T for the rotation of cosine c and sine s, templated for Ceres.
template <typename T>
Mat2<T> ellipseCovariance(const T& a, const T& b, const T& c, const T& s) {
  const T a2 = a * a, b2 = b * b;
  Mat2<T> S;
  S(0, 0) = c * c * a2 + s * s * b2;
  S(1, 1) = s * s * a2 + c * c * b2;
  S(0, 1) = S(1, 0) = c * s * (a2 - b2);
  return S;
}

/// Covariance R(angle) diag(a^2, b^2) R(angle)^T, templated for Ceres.
template <typename T>
Mat2<T> ellipseCovariance(const T& a, const T& b, const T& angle) {
  using std::cos;
  using std::sin;
  return ellipseCovariance<T>(a, b, cos(angle), sin(angle));
}

class Ellipse {
 public:
  /// The unit circle at the origin.
  Ellipse() = default;
  /// No validation here: check isValid(), or use a named constructor that returns optional.
  Ellipse(const Eigen::Vector2d& center, const Eigen::Vector2d& axes, double angle)
      : center_(center), axes_(axes), angle_(angle), cos_(std::cos(angle)), sin_(std::sin(angle)) {}

  /// Recovers the ellipse from a dual conic of any scale and sign (normalised internally).
  /// Returns nullopt when the matrix is not finite or does not describe a real ellipse.
  /// The result has a >= b and angle in (-pi/2, pi/2].
  static std::optional<Ellipse> fromDualConic(const Eigen::Matrix3d& C) {
    Eigen::Vector2d mean;
    Eigen::Matrix2d cov;
    if (!gaussianOfDualConic(C, &mean, &cov)) return std::nullopt;
    return fromGaussian(mean, cov);
  }

  /// The centre and sqrt(a b) of fromDualConic(C)'s ellipse, nullopt exactly where it has none,
  /// without its axes or angle: what placing an object at a depth needs, many times over.
  struct CentreAndSize {
    Eigen::Vector2d centre;
    double size;
  };
  static std::optional<CentreAndSize> centreAndSizeFromDualConic(const Eigen::Matrix3d& C) {
    Eigen::Vector2d mean;
    Eigen::Matrix2d cov;
    if (!gaussianOfDualConic(C, &mean, &cov) || !mean.allFinite() || !cov.allFinite()) return std::nullopt;
    const std::optional<Eigenvalues> e = positiveEigenvalues(cov);
    if (!e) return std::nullopt;
    return CentreAndSize{mean, std::sqrt(std::sqrt(e->l1 * e->l2))};
  }

  /// The ellipse whose Gaussian has this mean and covariance (covariance must be positive
  /// definite). The result has a >= b and angle in (-pi/2, pi/2].
  static std::optional<Ellipse> fromGaussian(const Eigen::Vector2d& mean, const Eigen::Matrix2d& cov) {
    if (!mean.allFinite() || !cov.allFinite()) return std::nullopt;
    const std::optional<Eigenvalues> e = positiveEigenvalues(cov);
    if (!e) return std::nullopt;
    const double half_diff = e->half_diff, radius = e->radius, q = e->q;
    // Axis a is the eigenvector of l1: (l1 - r, q) = (half_diff + radius, q), or (q, l1 - p) =
    // (q, radius - half_diff), whichever has no cancellation, turned so that the angle is in
    // (-pi/2, pi/2] (cosine > 0, or 0 with sine > 0). Projections make ellipses by the thousand
    // and few need the angle itself: angle() computes it when asked (no atan2, sin, cos here).
    double c = 1.0, s = 0.0;  // a circle: angle 0
    if (half_diff >= 0.0 && radius > 0.0) {
      c = half_diff + radius, s = q;
    } else if (half_diff < 0.0) {
      c = q < 0.0 ? -q : q, s = q < 0.0 ? half_diff - radius : radius - half_diff;
    }
    const double norm = scaledNorm(c, s);
    return Ellipse(mean, Eigen::Vector2d(std::sqrt(e->l1), std::sqrt(e->l2)), c / norm, s / norm);
  }

  /// The ellipse inscribed in an axis-aligned box (OA-SLAM's observation model).
  static std::optional<Ellipse> inscribedInBox(const Box& box) {
    if (!box.isValid() || !(box.width() > 0) || !(box.height() > 0)) return std::nullopt;
    const double a = 0.5 * box.width(), b = 0.5 * box.height();
    return a >= b ? Ellipse(box.center(), {a, b}, 0.0) : Ellipse(box.center(), {b, a}, M_PI / 2);
  }

  const Eigen::Vector2d& center() const { return center_; }
  const Eigen::Vector2d& axes() const { return axes_; }
  /// The angle given to the constructor, or for an ellipse recovered from a conic or Gaussian,
  /// in (-pi/2, pi/2].
  double angle() const { return std::isnan(angle_) ? std::atan2(sin_, cos_) : angle_; }

  /// Finite parameters and strictly positive semi-axes.
  bool isValid() const {
    return center_.allFinite() && std::isfinite(cos_) && std::isfinite(sin_) && std::isfinite(axes_(0)) &&
           std::isfinite(axes_(1)) && axes_(0) > 0.0 && axes_(1) > 0.0;
  }

  Eigen::Matrix2d rotation() const {
    Eigen::Matrix2d R;
    R << cos_, -sin_, sin_, cos_;
    return R;
  }

  /// Covariance of the Gaussian form: R diag(a^2, b^2) R^T.
  Eigen::Matrix2d covariance() const { return ellipseCovariance(axes_(0), axes_(1), cos_, sin_); }

  /// Dual conic, normalised so that C*(2,2) = -1.
  Eigen::Matrix3d dualConic() const {
    Eigen::Matrix3d C;
    C.topLeftCorner<2, 2>() = covariance() - center_ * center_.transpose();
    C.topRightCorner<2, 1>() = -center_;
    C.bottomLeftCorner<1, 2>() = -center_.transpose();
    C(2, 2) = -1.0;
    return C;
  }

  /// Primal conic x^T A x = 0 of the boundary, normalised so that A = [S^-1, -S^-1 c; .., c^T S^-1 c - 1].
  Eigen::Matrix3d conic() const {
    const Eigen::Matrix2d Sinv = covariance().inverse();
    Eigen::Matrix3d A;
    A.topLeftCorner<2, 2>() = Sinv;
    A.topRightCorner<2, 1>() = -Sinv * center_;
    A.bottomLeftCorner<1, 2>() = -(Sinv * center_).transpose();
    A(2, 2) = center_.dot(Sinv * center_) - 1.0;
    return A;
  }

  double area() const { return M_PI * axes_(0) * axes_(1); }

  /// Exact axis-aligned bounding box: half-widths sqrt(S(0,0)) and sqrt(S(1,1)).
  Box boundingBox() const {
    const Eigen::Matrix2d S = covariance();
    const double hx = std::sqrt(S(0, 0)), hy = std::sqrt(S(1, 1));
    return Box(center_(0) - hx, center_(1) - hy, center_(0) + hx, center_(1) + hy);
  }

  /// Mahalanobis radius of a point: 1 on the boundary, < 1 inside.
  double mahalanobisRadius(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = rotation().transpose() * (p - center_);
    return std::hypot(d(0) / axes_(0), d(1) / axes_(1));
  }

  /// True for points inside or on the boundary.
  bool contains(const Eigen::Vector2d& p) const { return mahalanobisRadius(p) <= 1.0; }

  /// The boundary point at parameter t: c + R (a cos t, b sin t).
  Eigen::Vector2d pointAt(double t) const {
    return center_ + rotation() * Eigen::Vector2d(axes_(0) * std::cos(t), axes_(1) * std::sin(t));
  }

  /// n boundary points, evenly spaced in the parameter t, counter-clockwise in the image frame.
  std::vector<Eigen::Vector2d> sampleBoundary(int n) const {
    std::vector<Eigen::Vector2d> points;
    if (n <= 0) return points;
    points.reserve(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) points.push_back(pointAt(2.0 * M_PI * i / n));
    return points;
  }

 private:
  /// The Gaussian of a dual conic (gaussianFromDualConic); false when C is not finite or
  /// C(2,2) vanishes (no finite centre).
  static bool gaussianOfDualConic(const Eigen::Matrix3d& C, Eigen::Vector2d* mean, Eigen::Matrix2d* cov) {
    if (!C.allFinite()) return false;
    const double scale = C.cwiseAbs().maxCoeff();
    if (!(scale > 0.0) || std::abs(C(2, 2)) <= 1e-14 * scale) return false;
    gaussianFromDualConic<double>(C, mean, cov);
    return true;
  }

  /// The closed-form eigen decomposition of a symmetric 2x2 covariance [p q; q r]: eigenvalues
  /// l1 >= l2 = (p + r) / 2 +- radius, radius = |((p - r) / 2, q)|.
  struct Eigenvalues {
    double l1, l2, half_diff, radius, q;
  };
  /// Nullopt unless the covariance is positive definite (l2 > 0, and not degenerate next to l1).
  static std::optional<Eigenvalues> positiveEigenvalues(const Eigen::Matrix2d& cov) {
    const double p = cov(0, 0), r = cov(1, 1), q = 0.5 * (cov(0, 1) + cov(1, 0));
    const double half_trace = 0.5 * (p + r), half_diff = 0.5 * (p - r);
    const double radius = scaledNorm(half_diff, q);
    const double l1 = half_trace + radius, l2 = half_trace - radius;
    if (!(l2 > 0.0) || !(l2 > 1e-12 * l1)) return std::nullopt;
    return Eigenvalues{l1, l2, half_diff, radius, q};
  }

  /// sqrt(x^2 + y^2) without overflow or underflow at any finite scale (as std::hypot, cheaper).
  static double scaledNorm(double x, double y) {
    const double m = std::max(std::abs(x), std::abs(y));
    if (!(m > 0.0)) return 0.0;
    const double u = x / m, v = y / m;
    return m * std::sqrt(u * u + v * v);
  }

  /// From the cosine and sine of the angle (a unit vector); the angle is computed when asked.
  Ellipse(const Eigen::Vector2d& center, const Eigen::Vector2d& axes, double cos_angle, double sin_angle)
      : center_(center),
        axes_(axes),
        angle_(std::numeric_limits<double>::quiet_NaN()),
        cos_(cos_angle),
        sin_(sin_angle) {}

  Eigen::Vector2d center_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d axes_ = Eigen::Vector2d::Ones();
  double angle_ = 0.0;            // NaN: not computed, angle() takes it from cos_ and sin_
  double cos_ = 1.0, sin_ = 0.0;  // of the angle: every rotation and covariance needs them
};

}  // namespace ellreloc
