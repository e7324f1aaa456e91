#pragma once
// Seeded random geometry shared by the tests.

#include <Eigen/Geometry>
#include <random>

#include "ellreloc/core.hpp"

namespace ellreloc::test {

inline double uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

inline Eigen::Matrix3d randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

inline Ellipse randomEllipse(std::mt19937& rng) {
  return Ellipse({uniform(rng, 50, 600), uniform(rng, 50, 400)}, {uniform(rng, 5, 120), uniform(rng, 5, 120)},
                 uniform(rng, -M_PI, M_PI));
}

inline Ellipsoid randomEllipsoid(std::mt19937& rng) {
  return Ellipsoid({uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)},
                   {uniform(rng, 0.05, 0.5), uniform(rng, 0.05, 0.5), uniform(rng, 0.05, 0.5)}, randomRotation(rng));
}

/// A camera 2.5-4 m from the origin looking at a point near it (up = world z).
inline Pose randomLookAtPose(std::mt19937& rng) {
  const Eigen::Vector3d center =
      Eigen::Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -0.5, 0.5)).normalized() *
      uniform(rng, 2.5, 4.0);
  const Eigen::Vector3d target(uniform(rng, -0.2, 0.2), uniform(rng, -0.2, 0.2), uniform(rng, -0.2, 0.2));
  return Pose::lookAt(center, target);
}

/// Distance between the camera centres of two poses.
inline double positionError(const Pose& a, const Pose& b) { return (a.center() - b.center()).norm(); }
/// Rotation angle between two poses, in degrees.
inline double rotationError(const Pose& a, const Pose& b) { return rotationErrorDeg(a.rotation(), b.rotation()); }

inline Intrinsics testIntrinsics() { return Intrinsics(525.0, 520.0, 319.5, 239.5, 640, 480); }

}  // namespace ellreloc::test
