#pragma once
/// \file projection.hpp
/// Projection of an ellipsoid into an image: C* = P Q* P^T (Hartley & Zisserman, eq. 8.9;
/// the paper's eq. 7).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <optional>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/core/ellipsoid.hpp"

namespace ellreloc {

/// C* = P Q* P^T, templated on the scalars so that Ceres can differentiate it. P or Q may be
/// plain numbers beside Jets: a number times a Jet gives the same values as a Jet without
/// derivatives times a Jet, for a fraction of the work.
template <typename TP, typename TQ = TP>
Mat3<typename Eigen::ScalarBinaryOpTraits<TP, TQ>::ReturnType> projectDualQuadric(const Eigen::Matrix<TP, 3, 4>& P,
                                                                                  const Eigen::Matrix<TQ, 4, 4>& Q) {
  return P * Q * P.transpose();
}

/// Depth range [near, far] of an ellipsoid (centre c, shape matrix M = R diag(a^2) R^T) along
/// the optical axis of a pose (R_cw, t_cw): z(c) -+ sqrt(r3^T M r3), r3 = third row of R_cw
/// (the ellipsoid's support function). Its image is an ellipse exactly when near > 0.
/// Templated for Ceres.
template <typename T>
void depthRange(const Mat3<T>& R_cw, const Eigen::Matrix<T, 3, 1>& t_cw, const Eigen::Matrix<T, 3, 1>& c,
                const Mat3<T>& M, T* near, T* far) {
  using std::sqrt;
  const Eigen::Matrix<T, 3, 1> r3 = R_cw.row(2).transpose();
  const T zc = r3.dot(c) + t_cw(2);
  const T half = sqrt(r3.dot(M * r3));
  *near = zc - half;
  *far = zc + half;
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
    case ProjectionStatus::Ok:
      return "ok";
    case ProjectionStatus::InvalidInput:
      return "invalid ellipsoid, intrinsics or pose";
    case ProjectionStatus::ContainsCamera:
      return "camera centre inside the ellipsoid";
    case ProjectionStatus::BehindCamera:
      return "ellipsoid behind the camera";
    case ProjectionStatus::NotAnEllipse:
      return "ellipsoid crosses the principal plane; image is not an ellipse";
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

/// An ellipsoid with what each of its projections needs, computed once: for projecting the same
/// map object at many poses.
struct ProjectableEllipsoid {
  Ellipsoid ellipsoid;
  Eigen::Matrix4d dual_quadric = Eigen::Matrix4d::Zero();
  Eigen::Matrix3d shape = Eigen::Matrix3d::Zero();
  double smallest_axis = 0.0, largest_axis = 0.0, axes_product = 0.0;
  bool valid = false;

  ProjectableEllipsoid() = default;
  explicit ProjectableEllipsoid(const Ellipsoid& e) : ellipsoid(e), valid(e.isValid()) {
    if (!valid) return;
    dual_quadric = e.dualQuadric();
    shape = e.shapeMatrix();
    smallest_axis = e.axes().minCoeff();
    largest_axis = e.axes().maxCoeff();
    axes_product = e.axes().prod();
  }
};

/// Bounds on the area of an ellipsoid's image, in square pixels, without projecting it.
struct ImageAreaBounds {
  double lower = 0.0;
  double upper = INFINITY;
};

/// Whenever an ellipsoid's image at a valid pose is an ellipse, its area lies within these
/// bounds; where it cannot be one (the sphere of the smallest semi-axis reaches the principal
/// plane), `lower` is infinite. The image contains the images of the sphere of the smallest
/// semi-axis and of the central section facing the camera, and lies within the image of the
/// sphere of the largest semi-axis:
///  - a sphere of radius r, centre at distance D and depth z > r, images to an ellipse of
///    normalised area pi r^2 sqrt(D^2 - r^2) / (z^2 - r^2)^(3/2) (a cone's section);
///  - the central section normal to the line of sight u has area pi a b c / sqrt(u^T M u), and
///    each of its points lies within the largest semi-axis of the centre, so its solid angle is
///    at least that area times D / (D^2 + a_max^2)^(3/2); a normalised image is at least as
///    large as its solid angle.
/// Pixels scale normalised areas by fx fy.
inline ImageAreaBounds imageAreaBounds(const ProjectableEllipsoid& e, const Intrinsics& K, const Pose& pose) {
  ImageAreaBounds b;
  if (!e.valid) return b;
  const Eigen::Vector3d x = pose.transform(e.ellipsoid.center());
  const double d2 = x.squaredNorm(), z2 = x(2) * x(2), pixels = K.fx * K.fy;
  const auto sphere = [&](double r) {
    const double h = z2 - r * r;
    return pixels * M_PI * r * r * std::sqrt(d2 - r * r) / (h * std::sqrt(h));
  };
  const double r_min = e.smallest_axis, r_max = e.largest_axis;
  if (!(x(2) > r_min)) {
    b.lower = INFINITY;
    return b;
  }
  const Eigen::Vector3d u = pose.rotation().transpose() * x;  // the line of sight (|u| = D) in the world
  const double section = M_PI * e.axes_product * std::sqrt(d2 / u.dot(e.shape * u));
  const double spread = d2 + r_max * r_max;
  b.lower = std::max(sphere(r_min), pixels * section * std::sqrt(d2) / (spread * std::sqrt(spread)));
  if (x(2) > r_max) b.upper = sphere(r_max);
  return b;
}

namespace detail {

/// Q* p3 for the last row p3 of P: the last column of C* = P Q* P^T is P (Q* p3), and its last
/// entry p3^T Q* p3 = r3^T M r3 - z_c^2 (Q* scaled to Q*_33 = -1, r3 and z_c the optical axis
/// and the centre's depth) is negative exactly when the principal plane misses the ellipsoid.
inline Eigen::Vector4d dualQuadricTimesLastRow(const ProjectableEllipsoid& e, const Eigen::Matrix<double, 3, 4>& P) {
  return e.dual_quadric * P.row(2).transpose();
}

/// Whether the image is an ellipse (the ellipsoid strictly in front of the principal plane):
/// the centre in front and the principal plane missing the ellipsoid. A camera inside the
/// ellipsoid fails it too, since every plane through the camera cuts the ellipsoid.
inline bool inFrontOfPrincipalPlane(const ProjectableEllipsoid& e, const Eigen::Matrix<double, 3, 4>& P,
                                    const Eigen::Vector4d& q3) {
  const double zc = P.row(2).head<3>().dot(e.ellipsoid.center()) + P(2, 3);
  return zc > 0.0 && P.row(2).dot(q3) < 0.0;
}

/// Why an ellipsoid has no elliptic image at a pose (inFrontOfPrincipalPlane failed).
inline ProjectionStatus whyNoEllipse(const ProjectableEllipsoid& e, const Pose& pose) {
  if (e.ellipsoid.contains(pose.center())) return ProjectionStatus::ContainsCamera;
  double near = 0.0, far = 0.0;
  depthRange<double>(pose.rotation(), pose.translation(), e.ellipsoid.center(), e.shape, &near, &far);
  return far <= 0.0 ? ProjectionStatus::BehindCamera : ProjectionStatus::NotAnEllipse;
}

}  // namespace detail

/// project() for a prepared ellipsoid and the camera matrix P = projectionMatrix(K, pose) of a
/// valid pose: the same result without recomputing what does not change.
inline Projection projectPrepared(const ProjectableEllipsoid& e, const Eigen::Matrix<double, 3, 4>& P,
                                  const Pose& pose) {
  Projection out;
  if (!e.valid) return out;
  if (!detail::inFrontOfPrincipalPlane(e, P, detail::dualQuadricTimesLastRow(e, P))) {
    out.status = detail::whyNoEllipse(e, pose);
    return out;
  }
  const std::optional<Ellipse> ellipse = Ellipse::fromDualConic(projectDualQuadric<double>(P, e.dual_quadric));
  if (!ellipse) {
    out.status = ProjectionStatus::NotAnEllipse;
    return out;
  }
  out.status = ProjectionStatus::Ok;
  out.ellipse = *ellipse;
  return out;
}

/// The centre of projectPrepared(e, P, pose)'s ellipse, or nullopt where the ellipsoid has no
/// elliptic image: C*(0:2, 2) / C*(2, 2), the last column of C* = P Q* P^T being P Q* p3 (p3 =
/// the last row of P). A fraction of the whole projection's cost.
inline std::optional<Eigen::Vector2d> projectedCentre(const ProjectableEllipsoid& e,
                                                      const Eigen::Matrix<double, 3, 4>& P) {
  if (!e.valid) return std::nullopt;
  const Eigen::Vector4d q3 = detail::dualQuadricTimesLastRow(e, P);
  if (!detail::inFrontOfPrincipalPlane(e, P, q3)) return std::nullopt;
  const Eigen::Vector3d last = P * q3;
  if (!last.allFinite() || !(std::abs(last(2)) > 0.0)) return std::nullopt;
  return Eigen::Vector2d(last(0) / last(2), last(1) / last(2));
}

/// Projects an ellipsoid with a world->camera pose. The image is an ellipse exactly when the
/// ellipsoid lies strictly in front of the camera's principal plane (z_c > 0 everywhere);
/// every other case returns a status, never a NaN.
inline Projection project(const Ellipsoid& ellipsoid, const Intrinsics& K, const Pose& pose) {
  if (!ellipsoid.isValid() || !K.isValid() || !pose.isValid()) return Projection{};
  return projectPrepared(ProjectableEllipsoid(ellipsoid), projectionMatrix(K, pose), pose);
}

}  // namespace ellreloc
