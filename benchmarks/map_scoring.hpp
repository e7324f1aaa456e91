#pragma once
// Scores an estimated object map against true objects: each true object is the ellipsoid
// inscribed in its yaw-only cuboid (axes = the cuboid's half-extents). Estimates are assigned
// to true objects of the same category by centre distance (Hungarian, within 30 cm); the rest
// are spurious. Recall counts the objects the map should have (`expected`: seen often enough);
// an estimate of a real object seen too rarely to be expected is neither found nor spurious. Errors: centre distance,
// yaw of the longest horizontal extent (objects whose footprint has an aspect of at least 1.3 only: a square's yaw is
// not defined), and the estimate's extent along each true axis relative to the true half-extent.
#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "ellreloc/core/object_map.hpp"
#include "ellreloc/core/statistics.hpp"
#include "ellreloc/mapping/hungarian.hpp"

namespace ellreloc::bench {

/// Direction (radians, mod pi) of the longest horizontal extent of an ellipsoid (z up).
inline double horizontalYaw(const Ellipsoid& e) {
  const Eigen::Matrix2d M = e.shapeMatrix().topLeftCorner<2, 2>();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(M);
  const Eigen::Vector2d v = eig.eigenvectors().col(1);
  return std::atan2(v.y(), v.x());
}

struct TruthObject {
  int category = 0;
  Ellipsoid ellipsoid;   ///< inscribed in the object's cuboid; rotation yaw-only
  bool expected = true;  ///< seen often enough that the map should have it
};

struct MapErrors {
  std::vector<double> centre, yaw, axis, axis_large;
  int found = 0, expected = 0, spurious = 0;
  int rarely_seen = 0;  ///< estimates of real objects that were not expected

  double recall() const { return expected > 0 ? static_cast<double>(found) / expected : std::nan(""); }
  /// The share of the map's objects that are real objects.
  double precision() const {
    const int real = found + rarely_seen;
    return real + spurious > 0 ? static_cast<double>(real) / (real + spurious) : std::nan("");
  }
};

inline double medianOrNan(std::vector<double> v) { return ellreloc::median(std::move(v), std::nan("")); }

/// Adds the errors of `estimate` against every true object to `err`.
inline void scoreMap(const std::vector<MapObject>& estimate, const std::vector<TruthObject>& truth, MapErrors* err) {
  for (const TruthObject& t : truth) err->expected += t.expected;
  if (truth.empty() || estimate.empty()) {
    err->spurious += static_cast<int>(estimate.size());
    return;
  }
  Eigen::MatrixXd cost(static_cast<long>(estimate.size()), static_cast<long>(truth.size()));
  for (size_t i = 0; i < estimate.size(); ++i)
    for (size_t j = 0; j < truth.size(); ++j)
      cost(static_cast<long>(i), static_cast<long>(j)) =
          (estimate[i].ellipsoid.center() - truth[j].ellipsoid.center()).norm() +
          (estimate[i].category == truth[j].category ? 0.0 : 10.0);
  const std::vector<int> a = hungarianAssignment(cost);
  for (size_t i = 0; i < estimate.size(); ++i) {
    if (a[i] < 0 || cost(static_cast<long>(i), a[i]) > 0.3) {
      ++err->spurious;
      continue;
    }
    if (!truth[static_cast<size_t>(a[i])].expected) {
      ++err->rarely_seen;
      continue;
    }
    const Ellipsoid& t = truth[static_cast<size_t>(a[i])].ellipsoid;
    const Ellipsoid& e = estimate[i].ellipsoid;
    ++err->found;
    err->centre.push_back((e.center() - t.center()).norm());
    const Eigen::Vector3d& half = t.axes();
    if (std::max(half.x(), half.y()) >= 1.3 * std::min(half.x(), half.y())) {
      double d = std::fmod(std::abs(horizontalYaw(e) - horizontalYaw(t)), M_PI);
      err->yaw.push_back(std::min(d, M_PI - d) * 180.0 / M_PI);
    }
    const Eigen::Matrix3d M = e.shapeMatrix();
    for (int k = 0; k < 3; ++k) {  // the estimate's extent along each true axis
      const Eigen::Vector3d u = t.rotation().col(k);
      const double rel = std::abs(std::sqrt(u.dot(M * u)) - half(k)) / half(k);
      err->axis.push_back(rel);
      if (half(k) >= 0.05) err->axis_large.push_back(rel);  // at least 2.5 voxels of 2 cm
    }
  }
}

}  // namespace ellreloc::bench
