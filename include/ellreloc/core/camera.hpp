#pragma once
/// \file camera.hpp
/// Pinhole intrinsics, and the projection matrix K [R_cw | t_cw] of a pose (core/pose.hpp).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "ellreloc/core/ellipsoid.hpp"
#include "ellreloc/core/pose.hpp"

namespace ellreloc {

/// Pinhole intrinsics of an undistorted image of width x height pixels.
struct Intrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;

  Intrinsics() = default;
  Intrinsics(double fx_, double fy_, double cx_, double cy_, int width_, int height_)
      : fx(fx_), fy(fy_), cx(cx_), cy(cy_), width(width_), height(height_) {}

  /// Finite, positive focal lengths and a positive image size.
  bool isValid() const {
    return std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) && std::isfinite(cy) && fx > 0 && fy > 0 &&
           width > 0 && height > 0;
  }

  bool operator==(const Intrinsics& o) const {
    return fx == o.fx && fy == o.fy && cx == o.cx && cy == o.cy && width == o.width && height == o.height;
  }
  bool operator!=(const Intrinsics& o) const { return !(*this == o); }

  Eigen::Matrix3d K() const {
    Eigen::Matrix3d k;
    k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
    return k;
  }

  /// Pixel of a point in camera coordinates (z must be > 0).
  Eigen::Vector2d project(const Eigen::Vector3d& x_c) const {
    return {fx * x_c(0) / x_c(2) + cx, fy * x_c(1) / x_c(2) + cy};
  }

  /// Unit bearing vector of a pixel.
  Eigen::Vector3d bearing(const Eigen::Vector2d& uv) const {
    return Eigen::Vector3d((uv(0) - cx) / fx, (uv(1) - cy) / fy, 1.0).normalized();
  }
};

/// Projection matrix P = K [R_cw | t_cw].
inline Eigen::Matrix<double, 3, 4> projectionMatrix(const Intrinsics& K, const Pose& pose) {
  // K's zeros spelled out: the full 3x3 product costs three times the multiplications.
  const Eigen::Matrix<double, 3, 4> Rt = pose.matrix3x4();
  Eigen::Matrix<double, 3, 4> P;
  P.row(0) = K.fx * Rt.row(0) + K.cx * Rt.row(2);
  P.row(1) = K.fy * Rt.row(1) + K.cy * Rt.row(2);
  P.row(2) = Rt.row(2);
  return P;
}

}  // namespace ellreloc
