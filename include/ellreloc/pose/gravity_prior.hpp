#pragma once
/// \file gravity_prior.hpp
/// The direction of gravity known in both frames: an IMU gives "up" in the camera frame, a
/// gravity-aligned map (visual-inertial SLAM, or a mapper that found the floor) gives it in the
/// map frame. The pair fixes two of the three rotation angles, which is what lets a single
/// ellipse-ellipsoid pair give a pose (Gaudilliere, Simon, Berger, "Perspective-1-Ellipsoid",
/// IJCV 2023) and disambiguates poses from two pairs.

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "ellreloc/core/camera.hpp"

namespace ellreloc {

struct GravityPrior {
  Eigen::Vector3d up_in_camera = -Eigen::Vector3d::UnitY();  ///< camera frame (x right, y down, z forward)
  Eigen::Vector3d up_in_map = Eigen::Vector3d::UnitZ();      ///< map (world) frame
  double sigma_deg = 2.0;                                    ///< accuracy of the tilt (IMU + map)

  /// Finite, non-zero directions and a positive finite sigma.
  bool isValid() const {
    return up_in_camera.allFinite() && up_in_map.allFinite() && up_in_camera.norm() > 1e-9 && up_in_map.norm() > 1e-9 &&
           std::isfinite(sigma_deg) && sigma_deg > 0.0;
  }

  /// The map's up seen from a camera at `pose`, unit length.
  Eigen::Vector3d predictedUp(const Pose& pose) const { return pose.rotation() * up_in_map.normalized(); }

  /// Angle in degrees between the camera's measured up and the one the pose predicts.
  double errorDeg(const Pose& pose) const {
    const Eigen::Vector3d a = predictedUp(pose), b = up_in_camera.normalized();
    return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
  }

  /// The test errorDeg(pose) <= max_deg prepared once for many poses: both ups of unit length
  /// and the bound as a cosine, so that a pose costs a rotation and a dot product, no arc tangent.
  struct Bound {
    Eigen::Vector3d up_in_map, up_in_camera;  ///< unit length
    double min_cos = -1.0;
    bool admits(const Pose& pose) const { return (pose.rotation() * up_in_map).dot(up_in_camera) >= min_cos; }
  };
  Bound bound(double max_deg) const {
    const double min_cos =
        max_deg >= 180.0 ? -std::numeric_limits<double>::infinity() : std::cos(max_deg * M_PI / 180.0);
    return {up_in_map.normalized(), up_in_camera.normalized(), min_cos};
  }

  /// The prior a gravity-aware host would measure at a known pose (tests, simulations).
  static GravityPrior atPose(const Pose& pose, const Eigen::Vector3d& up_in_map = Eigen::Vector3d::UnitZ(),
                             double sigma_deg = 2.0) {
    GravityPrior g;
    g.up_in_map = up_in_map.normalized();
    g.up_in_camera = pose.rotation() * g.up_in_map;
    g.sigma_deg = sigma_deg;
    return g;
  }
};

}  // namespace ellreloc
