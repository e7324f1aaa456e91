#pragma once
/// \file ellipsoid.hpp
/// Ellipsoids: centre (world), semi-axes, rotation object->world (columns = semi-axis
/// directions); dual quadric Q* = Z diag(a^2, b^2, c^2, -1) Z^T with Z = [R c; 0 1].

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <optional>
#include <vector>

namespace ellreloc {

/// The rotation matrix nearest to M in the Frobenius norm (SVD projection, det = +1).
inline Eigen::Matrix3d nearestRotation(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

/// True when R is finite, orthonormal within `tolerance` and has determinant +1.
inline bool isRotation(const Eigen::Matrix3d& R, double tolerance = 1e-6) {
  return R.allFinite() && (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= tolerance &&
         R.determinant() > 0.0;
}

class Ellipsoid {
 public:
  /// The unit sphere at the origin.
  Ellipsoid() = default;
  /// No validation here: check isValid(), or build from a dual quadric.
  Ellipsoid(const Eigen::Vector3d& center, const Eigen::Vector3d& axes, const Eigen::Matrix3d& rotation)
      : center_(center), axes_(axes), rotation_(rotation) {}

  /// Recovers the ellipsoid from a dual quadric of any scale and sign (OA-SLAM normalises
  /// Q*(3,3) = -1, gtsam_quadrics +1: both are accepted). Semi-axes come out in ascending
  /// order with a right-handed rotation. nullopt when Q is not a real ellipsoid.
  static std::optional<Ellipsoid> fromDualQuadric(const Eigen::Matrix4d& Q) {
    if (!Q.allFinite()) return std::nullopt;
    const double scale = Q.cwiseAbs().maxCoeff();
    if (!(scale > 0.0) || std::abs(Q(3, 3)) <= 1e-14 * scale) return std::nullopt;
    const Eigen::Matrix4d N = -0.5 * (Q + Q.transpose()) / Q(3, 3);  // now N(3,3) = -1
    const Eigen::Vector3d c = -N.topRightCorner<3, 1>();
    const Eigen::Matrix3d M = N.topLeftCorner<3, 3>() + c * c.transpose();  // R diag(axes^2) R^T
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(M);
    if (eig.info() != Eigen::Success) return std::nullopt;
    const Eigen::Vector3d l = eig.eigenvalues();
    if (!(l(0) > 0.0) || !(l(0) > 1e-14 * l(2))) return std::nullopt;
    Eigen::Matrix3d R = eig.eigenvectors();
    if (R.determinant() < 0) R.col(2) = -R.col(2);
    return Ellipsoid(c, l.cwiseSqrt(), R);
  }

  const Eigen::Vector3d& center() const { return center_; }
  const Eigen::Vector3d& axes() const { return axes_; }
  const Eigen::Matrix3d& rotation() const { return rotation_; }

  /// Finite parameters, strictly positive semi-axes and a proper rotation (tolerance 1e-6).
  bool isValid() const {
    return center_.allFinite() && axes_.allFinite() && axes_.minCoeff() > 0.0 && isRotation(rotation_);
  }

  /// Shape matrix R diag(a^2, b^2, c^2) R^T: the ellipsoid is (x-c)^T M^-1 (x-c) <= 1.
  Eigen::Matrix3d shapeMatrix() const { return rotation_ * axes_.cwiseAbs2().asDiagonal() * rotation_.transpose(); }

  /// Dual quadric, normalised so that Q*(3,3) = -1.
  Eigen::Matrix4d dualQuadric() const {
    Eigen::Matrix4d Q;
    Q.topLeftCorner<3, 3>() = shapeMatrix() - center_ * center_.transpose();
    Q.topRightCorner<3, 1>() = -center_;
    Q.bottomLeftCorner<1, 3>() = -center_.transpose();
    Q(3, 3) = -1.0;
    return Q;
  }

  double volume() const { return 4.0 / 3.0 * M_PI * axes_.prod(); }

  /// Exact axis-aligned bounding box: half-extent along world axis i is sqrt(M(i,i)).
  Eigen::AlignedBox3d boundingBox() const {
    const Eigen::Vector3d h = shapeMatrix().diagonal().cwiseSqrt();
    return Eigen::AlignedBox3d(center_ - h, center_ + h);
  }

  /// Mahalanobis radius of a world point: 1 on the surface, < 1 inside.
  double mahalanobisRadius(const Eigen::Vector3d& x) const {
    return (rotation_.transpose() * (x - center_)).cwiseQuotient(axes_).norm();
  }

  bool contains(const Eigen::Vector3d& x) const { return mahalanobisRadius(x) <= 1.0; }

  /// Surface point at polar angle theta in [0, pi] and azimuth phi.
  Eigen::Vector3d pointAt(double theta, double phi) const {
    const Eigen::Vector3d unit(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    return center_ + rotation_ * axes_.cwiseProduct(unit);
  }

  /// n surface points from a Fibonacci lattice on the unit sphere, mapped onto the ellipsoid.
  std::vector<Eigen::Vector3d> sampleSurface(int n) const {
    std::vector<Eigen::Vector3d> points;
    if (n <= 0) return points;
    points.reserve(static_cast<size_t>(n));
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
      const double z = 1.0 - 2.0 * (i + 0.5) / n;
      points.push_back(pointAt(std::acos(z), golden * i));
    }
    return points;
  }

 private:
  Eigen::Vector3d center_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d axes_ = Eigen::Vector3d::Ones();
  Eigen::Matrix3d rotation_ = Eigen::Matrix3d::Identity();
};

}  // namespace ellreloc
