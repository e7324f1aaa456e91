#pragma once
/// \file projection.hpp
/// Projection of an ellipsoid into an image: C* = P Q* P^T (Hartley & Zisserman, eq. 8.9;
/// the paper's eq. 7).

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/core/ellipsoid.hpp"

#include <Eigen/Core>

#include <cmath>
#include <optional>

namespace ellreloc {

/// C* = P Q* P^T, templated on the scalar so that Ceres can differentiate it.
template <typename T>
Mat3<T> projectDualQuadric(const Eigen::Matrix<T, 3, 4>& P, const Eigen::Matrix<T, 4, 4>& Q) {
  return P * Q * P.transpose();
}

enum class ProjectionStatus {
  Ok,
  InvalidInput,    ///< ellipsoid, intrinsics or pose not finite / not valid
  ContainsCamera,  ///< the camera centre is inside the ellipsoid
  BehindCamera,    ///< the whole ellipsoid is behind the camera
  NotAnEllipse,    ///< the ellipsoid crosses the camera's principal plane (its image is unbounded)
};

inline const char* toString(ProjectionStatus s) {
  switch (s) {
    case ProjectionStatus::Ok: return "ok";
    case ProjectionStatus::InvalidInput: return "invalid ellipsoid, intrinsics or pose";
    case ProjectionStatus::ContainsCamera: return "camera centre inside the ellipsoid";
    case ProjectionStatus::BehindCamera: return "ellipsoid behind the camera";
    case ProjectionStatus::NotAnEllipse: return "ellipsoid crosses the principal plane; image is not an ellipse";
  }
  return "unknown";
}

/// The image of an ellipsoid, or the reason there is none.
struct Projection {
  ProjectionStatus status = ProjectionStatus::InvalidInput;
  Ellipse ellipse;  ///< meaningful only when status == Ok

  bool ok() const { return status == ProjectionStatus::Ok; }
  explicit operator bool() const { return ok(); }
};

/// Projects an ellipsoid with a world->camera pose. The image is an ellipse exactly when the
/// ellipsoid lies strictly in front of the camera's principal plane (z_c > 0 everywhere);
/// every other case returns a status, never a NaN.
inline Projection project(const Ellipsoid& ellipsoid, const Intrinsics& K, const Pose& pose) {
  Projection out;
  if (!ellipsoid.isValid() || !K.isValid() || !pose.isValid()) return out;
  if (ellipsoid.contains(pose.center())) {
    out.status = ProjectionStatus::ContainsCamera;
    return out;
  }
  // Depth range of the ellipsoid along the optical axis: z(centre) +- sqrt(r3^T M r3),
  // r3 = third row of R_cw (support function of the ellipsoid).
  const Eigen::Vector3d r3 = pose.rotation().row(2).transpose();
  const double zc = r3.dot(ellipsoid.center()) + pose.translation()(2);
  const double half_depth = std::sqrt(r3.dot(ellipsoid.shapeMatrix() * r3));
  if (zc + half_depth <= 0.0) {
    out.status = ProjectionStatus::BehindCamera;
    return out;
  }
  if (zc - half_depth <= 0.0) {
    out.status = ProjectionStatus::NotAnEllipse;
    return out;
  }
  const Eigen::Matrix3d C = projectDualQuadric<double>(projectionMatrix(K, pose), ellipsoid.dualQuadric());
  const std::optional<Ellipse> e = Ellipse::fromDualConic(C);
  if (!e) {
    out.status = ProjectionStatus::NotAnEllipse;
    return out;
  }
  out.status = ProjectionStatus::Ok;
  out.ellipse = *e;
  return out;
}

}  // namespace ellreloc
