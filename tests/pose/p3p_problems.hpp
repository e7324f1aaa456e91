#pragma once
// Random P3P instances shared by the tests and the benchmark (PoseLib's habit: one problem
// generator for both).

#include <Eigen/Geometry>
#include <array>
#include <random>

#include "ellreloc/core/camera.hpp"

namespace ellreloc::test {

struct P3PInstance {
  std::array<Eigen::Vector3d, 3> bearings;
  std::array<Eigen::Vector3d, 3> points;
  Pose truth;
};

/// A random camera and three points at depths 1-10 whose bearings lie within a cone of
/// `half_angle_deg` around a random direction of the camera's forward hemisphere.
inline P3PInstance randomP3PInstance(std::mt19937& rng, double half_angle_deg) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  P3PInstance inst;
  const Eigen::Matrix3d R =
      Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();
  const Eigen::Vector3d t(normal(rng), normal(rng), normal(rng));
  inst.truth = Pose(R, t);
  Eigen::Vector3d axis(0.3 * normal(rng), 0.3 * normal(rng), 1.0);
  axis.normalize();
  const Eigen::Vector3d u = axis.unitOrthogonal(), v = axis.cross(u);
  const double max_angle = half_angle_deg * M_PI / 180.0;
  for (int i = 0; i < 3; ++i) {
    const double ang = max_angle * std::sqrt(uni(rng)), phi = 2.0 * M_PI * uni(rng);
    const Eigen::Vector3d dir = std::cos(ang) * axis + std::sin(ang) * (std::cos(phi) * u + std::sin(phi) * v);
    const Eigen::Vector3d x_c = dir * (1.0 + 9.0 * uni(rng));
    inst.bearings[i] = dir.normalized();
    inst.points[i] = R.transpose() * (x_c - t);
  }
  return inst;
}

}  // namespace ellreloc::test
