#pragma once
/// \file ellipsoid_builder.hpp
/// The paper's "Accurate Ellipsoids Generation": objects stand on the ground, so their pose
/// reduces to a yaw about gravity. The yaw is that of the smallest rectangle around the object's
/// points (the mapper's: one per occupied voxel, the mean of the depth points in it) projected
/// onto the ground plane (the paper: the main axis of their PCA, which YawMethod::Pca keeps);
/// extents along the two ground axes and gravity come from robust percentiles of the point
/// coordinates; the ellipsoid is the one inscribed in that
/// cuboid (eqs. 5-6: Q* = Z^T diag(l^2/4, w^2/4, h^2/4, -1) Z). Compiled in
/// src/mapping/ellipsoid_builder.cpp.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "ellreloc/core/ellipsoid.hpp"

namespace ellreloc {

/// An oriented cuboid: centre, half-extents along its axes, rotation (cuboid -> world).
struct Cuboid {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();

  /// The eight corners, for display.
  std::array<Eigen::Vector3d, 8> corners() const {
    std::array<Eigen::Vector3d, 8> c;
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d s((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0);
      c[static_cast<size_t>(i)] = center + rotation * s.cwiseProduct(half);
    }
    return c;
  }
  /// The inscribed ellipsoid (semi-axes = half-extents).
  Ellipsoid inscribedEllipsoid() const { return Ellipsoid(center, half, rotation); }
};

/// How the yaw is found from the ground-plane footprint of the points.
enum class YawMethod {
  Pca,  ///< main axis of a (trimmed) PCA, the paper's method
  /// the smallest rectangle around the trimmed footprint (rotating calipers), polished to the
  /// smallest rectangle of its percentiles within 4 degrees
  MinAreaRectangle,
};

struct EllipsoidBuilderOptions {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< against gravity, in world coordinates
  /// The smallest rectangle is the default: PCA leans towards the diagonal of a box whose back
  /// was never seen, and of a square footprint (docs/benchmarks.md, "Object mapping").
  YawMethod yaw = YawMethod::MinAreaRectangle;
  /// Extents span these percentiles of the point coordinates along each axis, which ignores
  /// a few outlier voxels that survived the label filter.
  double low_percentile = 0.01;
  double high_percentile = 0.99;
  /// Added to each half-extent. The mapper's points lie on the measured surface, so the
  /// percentile span needs no padding by default.
  double extent_padding = 0.0;
  size_t min_points = 8;  ///< fewer points: no ellipsoid
};

struct BuiltEllipsoid {
  Ellipsoid ellipsoid;
  Cuboid cuboid;
  double yaw = 0.0;  ///< radians, of the cuboid's first axis in the ground plane
};

namespace detail {
/// The direction of the longer side of the smallest-area rectangle enclosing 2D points: the
/// rectangle has a side on an edge of the convex hull, so each hull edge is tried.
std::optional<Eigen::Vector2d> minAreaRectangleAxis(std::vector<Eigen::Vector2d> p);
/// interpolatedQuantile(values, low) and (values, high), to the bit, with `scratch` for room.
std::pair<double, double> quantilePair(const std::vector<double>& values, double low, double high,
                                       std::vector<double>* scratch);
}  // namespace detail

/// A right-handed world basis (e1, e2, up) with e1, e2 spanning the ground plane.
inline Eigen::Matrix3d groundBasis(const Eigen::Vector3d& up) {
  const Eigen::Vector3d g = up.normalized();
  const Eigen::Vector3d helper = std::abs(g.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d e1 = (helper - helper.dot(g) * g).normalized();
  Eigen::Matrix3d B;
  B << e1, g.cross(e1), g;
  return B;
}

/// Builds the yaw-only cuboid and its inscribed ellipsoid from an object's points
/// (world coordinates). nullopt with fewer than options.min_points points, a zero or
/// non-finite `up`, or a degenerate (flat) point set.
std::optional<BuiltEllipsoid> buildEllipsoid(const std::vector<Eigen::Vector3d>& points,
                                             const EllipsoidBuilderOptions& options = {});

}  // namespace ellreloc
