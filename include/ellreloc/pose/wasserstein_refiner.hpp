#pragma once
/// \file wasserstein_refiner.hpp
/// Camera pose refinement from ellipse-ellipsoid correspondences (the paper's eq. 8):
///   minimise over (R, t)  sum_i rho( |r_i|^2 / s_i^2 )  [+ points]
/// where r_i is a 6-vector with |r_i|^2 = W2^2(observed ellipse_i, projection of ellipsoid_i)
/// (core/distances.hpp, wasserstein2Residual) and s_i = sqrt(a_i b_i), the observed ellipse's
/// geometric-mean radius: dividing by it makes the term scale-free, so a 20-px cup and a
/// 200-px monitor that are both off by 10% of their size weigh alike. Optional keypoint
/// reprojection residuals (the paper's "objects + points") and a gravity prior
/// (|R up_map - up_camera|^2 / sigma^2, not robustified) join the same problem.
///
/// The default backend is Levenberg-Marquardt on a left perturbation of the pose, derivatives
/// by forward automatic differentiation (Ceres Jets) seeded analytically, robust losses by
/// iteratively reweighted least squares; a step is accepted only when the robust cost
/// decreases. The Ceres backend builds a ceres::Problem (quaternion on
/// EigenQuaternionManifold, translation in R^3, ceres::HuberLoss / CauchyLoss). Either way the
/// returned pose never has a higher cost than the one given: if it would, the given pose is
/// returned and `fell_back` says so.

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/core/ellipsoid.hpp"
#include "ellreloc/pose/gravity_prior.hpp"

namespace ellreloc {

enum class RobustLoss { None, Huber, Cauchy };

/// rho(s) of a robust loss on a squared residual s with scale c, in Ceres' convention: Huber
/// rho = s for s <= c^2, 2 c sqrt(s) - c^2 beyond; Cauchy rho = c^2 log(1 + s / c^2). Writes
/// rho'(s) to `drho` when given.
inline double robustLoss(RobustLoss type, double c, double s, double* drho = nullptr) {
  double rho = s, d = 1.0;
  if (type == RobustLoss::Huber && s > c * c) {
    const double r = std::sqrt(s);
    rho = 2.0 * c * r - c * c, d = c / r;
  } else if (type == RobustLoss::Cauchy) {
    rho = c * c * std::log1p(s / (c * c)), d = 1.0 / (1.0 + s / (c * c));
  }
  if (drho) *drho = d;
  return rho;
}

/// Which solver minimises the cost; both use the same residuals and losses.
enum class RefinerBackend {
  LevenbergMarquardt,  ///< our 6-DoF solver with analytically seeded Jets (the faster: default)
  Ceres,               ///< ceres::Problem with EigenQuaternionManifold x R^3 and autodiff
};

struct RefinerOptions {
  RefinerBackend backend = RefinerBackend::LevenbergMarquardt;
  RobustLoss object_loss = RobustLoss::Cauchy;
  double object_loss_scale = 0.5;  ///< in normalised W2 units (W2 / sqrt(a b))
  RobustLoss point_loss = RobustLoss::Huber;
  double point_sigma_px = 2.0;    ///< keypoint residuals are divided by this
  double point_loss_scale = 3.0;  ///< in units of point_sigma_px
  double point_weight = 1.0;      ///< multiplies every point term
  int max_iterations = 30;
  /// Relative cost decrease that counts as converged. Steps below 1e-6 move a relocalized pose
  /// by hundredths of a millimetre (at most 3 mm on the real sets), far below its error.
  double function_tolerance = 1e-6;
};

/// One ellipse-ellipsoid correspondence.
struct EllipseMatch {
  Ellipse observed;
  Ellipsoid ellipsoid;
  /// The observed ellipse's expected error in units of its size (1: a box's ellipse); the
  /// residual is divided by sigma * sqrt(a b), so a more reliable ellipse weighs more. A
  /// match whose sigma is not a positive number is left out.
  double sigma = 1.0;
};

/// One 2D keypoint matched to a 3D map point.
struct PointMatch {
  Eigen::Vector2d observed;
  Eigen::Vector3d point;
};

struct RefinementResult {
  Pose pose;                  ///< the refined pose (the initial one when nothing improved)
  double initial_cost = 0.0;  ///< robust cost at the given pose
  double final_cost = 0.0;    ///< robust cost at the returned pose (<= initial_cost)
  int iterations = 0;
  bool converged = false;                ///< stopped on the tolerance, not on the iteration cap
  bool fell_back = false;                ///< returned the given pose unchanged
  std::string message;                   ///< why it fell back, or empty
  std::vector<double> object_residuals;  ///< normalised W2 per match at the returned pose; -1 if not projectable
  std::vector<double> point_residuals;   ///< reprojection error in px per point; -1 if behind the camera
};

/// Refines `initial`. Matches whose ellipsoid does not project at the initial pose are left
/// out (their residual is -1). With no usable match it falls back and says why. A gravity
/// prior keeps the pose's tilt near the measured one; with it one object suffices.
RefinementResult refinePose(const Intrinsics& K, const Pose& initial, const std::vector<EllipseMatch>& objects,
                            const std::vector<PointMatch>& points = {}, const RefinerOptions& options = {},
                            const std::optional<GravityPrior>& gravity = std::nullopt);

}  // namespace ellreloc
