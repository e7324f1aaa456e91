#pragma once
/// \file pose.hpp
/// A camera pose (world->camera rigid transform), a pose with a cost, and the rotation error
/// between two poses.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "ellreloc/core/ellipsoid.hpp"

namespace ellreloc {

/// World->camera rigid transform: x_c = R_cw x_w + t_cw.
class Pose {
 public:
  Pose() = default;
  Pose(const Eigen::Matrix3d& R_cw, const Eigen::Vector3d& t_cw) : R_(R_cw), t_(t_cw) {}

  /// From a camera->world pose (camera centre and orientation in the world), as TUM
  /// trajectory files store it.
  static Pose fromCameraToWorld(const Eigen::Matrix3d& R_wc, const Eigen::Vector3d& center) {
    return Pose(R_wc.transpose(), -R_wc.transpose() * center);
  }

  /// A camera at `eye` looking at `target`, image x horizontal (perpendicular to `up` and the
  /// optical axis), image y pointing away from `up` (down for up = world z).
  static Pose lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                     const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ()) {
    Eigen::Matrix3d R_wc;
    R_wc.col(2) = (target - eye).normalized();
    Eigen::Vector3d x = R_wc.col(2).cross(up);
    if (x.norm() < 1e-6)
      x = std::abs(R_wc(0, 2)) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();  // along `up`
    R_wc.col(0) = x.normalized();
    R_wc.col(1) = R_wc.col(2).cross(R_wc.col(0));
    return fromCameraToWorld(R_wc, eye);
  }

  const Eigen::Matrix3d& rotation() const { return R_; }
  const Eigen::Vector3d& translation() const { return t_; }

  /// Camera centre in world coordinates: -R^T t.
  Eigen::Vector3d center() const { return -R_.transpose() * t_; }

  /// World point -> camera coordinates.
  Eigen::Vector3d transform(const Eigen::Vector3d& x_w) const { return R_ * x_w + t_; }

  /// The camera->world transform as a Pose object (its "rotation" is R_wc).
  Pose inverse() const { return Pose(R_.transpose(), -R_.transpose() * t_); }

  /// (this * other)(x) = this(other(x)).
  Pose operator*(const Pose& other) const { return Pose(R_ * other.R_, R_ * other.t_ + t_); }

  Eigen::Matrix<double, 3, 4> matrix3x4() const {
    Eigen::Matrix<double, 3, 4> M;
    M << R_, t_;
    return M;
  }

  bool isValid() const { return t_.allFinite() && isRotation(R_); }

 private:
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_ = Eigen::Vector3d::Zero();
};

/// A pose with the cost that ranked it (lower is better): a solver's or a score's.
struct ScoredPose {
  Pose pose;
  double cost = 0.0;
};

/// Rotation angle of R_a^T R_b in degrees (the rotation error of docs/formats.md).
/// Computed through a quaternion (2 atan2), which stays accurate for tiny angles where
/// acos((trace - 1) / 2) does not.
inline double rotationErrorDeg(const Eigen::Matrix3d& Ra, const Eigen::Matrix3d& Rb) {
  const Eigen::Quaterniond q(Eigen::Matrix3d(Ra.transpose() * Rb));
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w())) * 180.0 / M_PI;
}

}  // namespace ellreloc
