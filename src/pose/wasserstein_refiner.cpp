#include "ellreloc/pose/wasserstein_refiner.hpp"

#include <ceres/ceres.h>
#include <ceres/jet.h>
#include <ceres/rotation.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/projection.hpp"

namespace ellreloc {

namespace {

using Jet = ceres::Jet<double, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

/// A gravity prior with unit directions and sigma in radians: the chord |R up_map - up_camera|
/// is the tilt error in radians while it is small.
struct UnitGravity {
  Eigen::Vector3d up_in_map, up_in_camera;
  double sigma_rad;
};

/// The camera-frame dual quadric of an ellipsoid (dual quadric Q) at a pose: T Q T^T with T = [R t; 0 1].
Eigen::Matrix4d cameraDualQuadric(const Eigen::Matrix4d& Q, const Pose& pose) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = pose.rotation();
  T.topRightCorner<3, 1>() = pose.translation();
  return T * Q * T.transpose();
}

/// Evaluates residuals (and optionally Jacobians w.r.t. the left perturbation
/// delta = (omega, v): R <- Exp(omega) R, t <- Exp(omega) t + v) at `pose`.
struct Problem {
  const Intrinsics& K;
  std::vector<const EllipseMatch*> objects;
  std::vector<ProjectableEllipsoid> prepared;  // each object's ellipsoid, for its many projections
  std::vector<double> object_scale;            // sqrt(a b) of each observed ellipse
  const std::vector<PointMatch>& points;
  const RefinerOptions& opt;
  const UnitGravity* gravity = nullptr;

  /// The sigma-normalised gravity residual.
  Eigen::Vector3d gravityResidual(const Pose& pose) const {
    return (pose.rotation() * gravity->up_in_map - gravity->up_in_camera) / gravity->sigma_rad;
  }

  /// Robust cost; false when an object no longer projects to an ellipse or a point is behind.
  bool cost(const Pose& pose, double* total) const {
    double sum = 0.0;
    if (!objects.empty() && !pose.isValid()) return false;  // no projection, as project() says
    const Eigen::Matrix<double, 3, 4> P = projectionMatrix(K, pose);
    for (size_t i = 0; i < objects.size(); ++i) {
      const Projection p = projectPrepared(prepared[i], P, pose);
      if (!p) return false;
      const double s = wasserstein2Squared(objects[i]->observed, p.ellipse) / (object_scale[i] * object_scale[i]);
      sum += robustLoss(opt.object_loss, opt.object_loss_scale, s);
    }
    for (const PointMatch& m : points) {
      const Eigen::Vector3d x = pose.transform(m.point);
      if (!(x(2) > 0.0)) return false;
      const double s = (K.project(x) - m.observed).squaredNorm() / (opt.point_sigma_px * opt.point_sigma_px);
      sum += opt.point_weight * robustLoss(opt.point_loss, opt.point_loss_scale, s);
    }
    if (gravity) sum += gravityResidual(pose).squaredNorm();
    *total = sum;
    return std::isfinite(sum);
  }

  /// Gauss-Newton normal equations (IRLS-weighted) at the pose.
  /// Flattened: every Jet operation inlined. Left to itself GCC calls Eigen's 6-vector
  /// kernels of the Jets out of line, which cost a quarter of the refinement.
  [[gnu::flatten]] bool normalEquations(const Pose& pose, Mat6* H, Vec6* g) const {
    H->setZero();
    g->setZero();
    // M(delta) = [Exp(omega) | v] maps the current camera frame to the perturbed one. At
    // delta = 0, C*(delta) = K M Qc M^T K^T has value K Qc[0:3,0:3] K^T and derivatives
    // dC/dd_k = G_k + G_k^T with G_k = K E_k N, N = Qc[:, 0:3] K^T and E_k = dM/dd_k:
    // [[e_k]x | 0] for omega_k, [0 | e_k] for v_k. Seeding C* as a Jet with these
    // derivatives is exact and much cheaper than pushing Jets through the 4x4 products.
    const Eigen::Matrix3d Kd = K.K();
    Jet delta[6];
    for (int k = 0; k < 6; ++k) delta[k] = Jet(0.0, k);
    Eigen::Matrix<Jet, 3, 4> M;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) M(r, c) = Jet(r == c ? 1.0 : 0.0);
      M(r, 3) = delta[3 + r];
    }
    M(0, 1) = -delta[2], M(0, 2) = delta[1], M(1, 0) = delta[2], M(1, 2) = -delta[0], M(2, 0) = -delta[1],
         M(2, 1) = delta[0];  // first-order Exp(omega) = I + [omega]x: exact for the derivative
    for (size_t i = 0; i < objects.size(); ++i) {
      const Eigen::Matrix4d Qc = cameraDualQuadric(prepared[i].dual_quadric, pose);
      const Eigen::Matrix<double, 4, 3> N = Qc.leftCols<3>() * Kd.transpose();
      const Eigen::Matrix3d C0 = Kd * N.topRows<3>();
      Mat3<Jet> C;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) C(r, c) = Jet(C0(r, c));
      for (int k = 0; k < 6; ++k) {
        Eigen::Matrix3d EN;  // E_k N
        if (k < 3) {
          const Eigen::Vector3d e = Eigen::Vector3d::Unit(k);
          for (int c = 0; c < 3; ++c) EN.col(c) = e.cross(N.block<3, 1>(0, c));
        } else {
          EN.setZero();
          EN.row(k - 3) = N.row(3);
        }
        const Eigen::Matrix3d G = Kd * EN;
        const Eigen::Matrix3d dC = G + G.transpose();
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) C(r, c).v(k) = dC(r, c);
      }
      Vec2<Jet> mean;
      Mat2<Jet> cov;
      gaussianFromDualConic<Jet>(C, &mean, &cov);
      const Ellipse& obs = objects[i]->observed;
      Jet r[6];
      wasserstein2Residual<Jet>(obs.center().cast<Jet>(), obs.covariance().cast<Jet>(), mean, cov, r);
      Eigen::Matrix<double, 6, 6> J;  // rows: residual components
      Vec6 res;
      for (int k = 0; k < 6; ++k) {
        res(k) = r[k].a / object_scale[i];
        J.row(k) = r[k].v.transpose() / object_scale[i];
      }
      if (!J.allFinite() || !res.allFinite()) return false;
      double drho = 0.0;
      robustLoss(opt.object_loss, opt.object_loss_scale, res.squaredNorm(), &drho);
      *H += drho * J.transpose() * J;
      *g += drho * J.transpose() * res;
    }
    for (const PointMatch& m : points) {
      const Eigen::Vector3d xc = pose.transform(m.point);
      Eigen::Matrix<Jet, 3, 1> x = M.leftCols<3>() * xc.cast<Jet>() + M.col(3);
      const Jet u = K.fx * x(0) / x(2) + K.cx, v = K.fy * x(1) / x(2) + K.cy;
      Eigen::Matrix<double, 2, 6> J;
      Eigen::Vector2d res((u.a - m.observed(0)) / opt.point_sigma_px, (v.a - m.observed(1)) / opt.point_sigma_px);
      J.row(0) = u.v.transpose() / opt.point_sigma_px;
      J.row(1) = v.v.transpose() / opt.point_sigma_px;
      double drho = 0.0;
      robustLoss(opt.point_loss, opt.point_loss_scale, res.squaredNorm(), &drho);
      *H += opt.point_weight * drho * J.transpose() * J;
      *g += opt.point_weight * drho * J.transpose() * res;
    }
    if (gravity) {
      // d/d omega of Exp(omega) R up = -[R up]x at omega = 0; translation does not enter.
      const Eigen::Vector3d up = pose.rotation() * gravity->up_in_map;
      Eigen::Matrix<double, 3, 6> J = Eigen::Matrix<double, 3, 6>::Zero();
      J.leftCols<3>() << 0, up(2), -up(1), -up(2), 0, up(0), up(1), -up(0), 0;
      J /= gravity->sigma_rad;
      *H += J.transpose() * J;
      *g += J.transpose() * gravityResidual(pose);
    }
    return H->allFinite() && g->allFinite();
  }
};

Pose applyDelta(const Pose& pose, const Vec6& d) {
  double R[9];
  ceres::AngleAxisToRotationMatrix(d.data(), ceres::RowMajorAdapter3x3(R));
  const Eigen::Matrix3d dR = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R);
  // Re-orthonormalise: many small rotations accumulate rounding. The product of two rotations
  // is one to rounding, so its unit quaternion is as good as the nearest rotation and far cheaper
  // than an SVD.
  const Eigen::Quaterniond q(Eigen::Matrix3d(dR * pose.rotation()));
  return Pose(q.normalized().toRotationMatrix(), dR * pose.translation() + d.tail<3>());
}

/// Ceres cost of one ellipse-ellipsoid match: the normalised 6-vector W2 residual at the pose
/// (quaternion x, y, z, w; translation). A pose that puts the ellipsoid across the principal
/// plane is rejected (returns false), so Ceres shortens the step.
struct CeresObjectCost {
  CeresObjectCost(const Ellipse& observed, const Ellipsoid& e, const Intrinsics& K, double scale)
      : mean(observed.center()),
        cov(observed.covariance()),
        Q(e.dualQuadric()),
        M(e.shapeMatrix()),
        c(e.center()),
        K(K.K()),
        inv_scale(1.0 / scale) {}
  /// Flattened, as normalEquations: GCC calls Eigen's kernels for the Jets out of line. K, Q and
  /// the scale stay plain numbers (projectDualQuadric says why).
  template <typename T>
  [[gnu::flatten]] bool operator()(const T* q, const T* t, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> quat(q);
    const Mat3<T> R = quat.normalized().toRotationMatrix();
    const Eigen::Matrix<T, 3, 1> tt(t[0], t[1], t[2]);
    // The ellipsoid must stay strictly in front of the camera (as in project()).
    T near, far;
    depthRange<T>(R, tt, c.cast<T>(), M.cast<T>(), &near, &far);
    if (!(near > T(0))) return false;
    Eigen::Matrix<T, 3, 4> P;
    P << R, tt;
    P = K * P;
    const Mat3<T> C = projectDualQuadric<T, double>(P, Q);
    Vec2<T> m;
    Mat2<T> S;
    gaussianFromDualConic<T>(C, &m, &S);
    wasserstein2Residual<T>(mean.cast<T>(), cov.cast<T>(), m, S, r);
    for (int k = 0; k < 6; ++k) r[k] *= inv_scale;
    return true;
  }
  Eigen::Vector2d mean;
  Eigen::Matrix2d cov;
  Eigen::Matrix4d Q;
  Eigen::Matrix3d M;
  Eigen::Vector3d c;
  Eigen::Matrix3d K;
  double inv_scale;
};

struct CeresPointCost {
  CeresPointCost(const PointMatch& m, const Intrinsics& K, double sigma) : m(m), K(K), inv_sigma(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* q, const T* t, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> quat(q);
    const Eigen::Matrix<T, 3, 1> x = quat.normalized() * m.point.cast<T>() + Eigen::Matrix<T, 3, 1>(t[0], t[1], t[2]);
    if (!(x(2) > T(0))) return false;
    r[0] = (T(K.fx) * x(0) / x(2) + T(K.cx) - T(m.observed(0))) * T(inv_sigma);
    r[1] = (T(K.fy) * x(1) / x(2) + T(K.cy) - T(m.observed(1))) * T(inv_sigma);
    return true;
  }
  PointMatch m;
  Intrinsics K;
  double inv_sigma;
};

/// Ceres cost of the gravity prior: (R up_map - up_camera) / sigma.
struct CeresGravityCost {
  explicit CeresGravityCost(const UnitGravity& g) : g(g) {}
  template <typename T>
  bool operator()(const T* q, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> quat(q);
    const Eigen::Matrix<T, 3, 1> up = quat.normalized() * g.up_in_map.cast<T>();
    for (int k = 0; k < 3; ++k) r[k] = (up(k) - T(g.up_in_camera(k))) / T(g.sigma_rad);
    return true;
  }
  UnitGravity g;
};

ceres::LossFunction* makeLoss(RobustLoss type, double scale, double weight) {
  ceres::LossFunction* loss = nullptr;
  if (type == RobustLoss::Huber) loss = new ceres::HuberLoss(scale);
  if (type == RobustLoss::Cauchy) loss = new ceres::CauchyLoss(scale);
  if (weight != 1.0) loss = new ceres::ScaledLoss(loss, weight, ceres::TAKE_OWNERSHIP);
  return loss;
}

/// Minimises the same cost as Problem with Ceres; returns the pose and the iteration count.
Pose solveWithCeres(const Problem& problem, const Pose& initial, const RefinerOptions& opt, int* iterations,
                    bool* converged) {
  Eigen::Quaterniond q(initial.rotation());
  Eigen::Vector3d t = initial.translation();
  ceres::Problem::Options popt;
  ceres::Problem cp(popt);
  for (size_t i = 0; i < problem.objects.size(); ++i) {
    auto* cost = new ceres::AutoDiffCostFunction<CeresObjectCost, 6, 4, 3>(new CeresObjectCost(
        problem.objects[i]->observed, problem.objects[i]->ellipsoid, problem.K, problem.object_scale[i]));
    cp.AddResidualBlock(cost, makeLoss(opt.object_loss, opt.object_loss_scale, 1.0), q.coeffs().data(), t.data());
  }
  for (const PointMatch& m : problem.points) {
    auto* cost =
        new ceres::AutoDiffCostFunction<CeresPointCost, 2, 4, 3>(new CeresPointCost(m, problem.K, opt.point_sigma_px));
    cp.AddResidualBlock(cost, makeLoss(opt.point_loss, opt.point_loss_scale, opt.point_weight), q.coeffs().data(),
                        t.data());
  }
  if (problem.gravity)
    cp.AddResidualBlock(new ceres::AutoDiffCostFunction<CeresGravityCost, 3, 4>(new CeresGravityCost(*problem.gravity)),
                        nullptr, q.coeffs().data());
  cp.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = opt.function_tolerance;
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &cp, &summary);
  *iterations = static_cast<int>(summary.iterations.size());
  *converged = summary.termination_type == ceres::CONVERGENCE;
  return Pose(nearestRotation(q.normalized().toRotationMatrix()), t);
}

/// Levenberg-Marquardt on a left perturbation of the pose: a step is accepted only when the
/// robust cost decreases. `cost_io` holds the cost at `initial` and receives the final one.
Pose solveWithLevenbergMarquardt(const Problem& problem, const Pose& initial, const RefinerOptions& options,
                                 double* cost_io, int* iterations, bool* converged) {
  Pose pose = initial;
  double& cost = *cost_io;
  double lambda = 1e-4;
  for (int it = 0; it < options.max_iterations; ++it) {
    *iterations = it + 1;
    Mat6 H;
    Vec6 g;
    if (!problem.normalEquations(pose, &H, &g)) break;
    bool accepted = false;
    while (lambda < 1e10) {
      Mat6 A = H;
      A.diagonal() += lambda * (H.diagonal().cwiseMax(1e-9));
      const Vec6 step = -A.ldlt().solve(g);
      if (step.allFinite()) {
        const Pose trial = applyDelta(pose, step);
        double trial_cost;
        if (problem.cost(trial, &trial_cost) && trial_cost < cost) {
          const double decrease = cost - trial_cost;
          pose = trial;
          cost = trial_cost;
          lambda = std::max(lambda / 10.0, 1e-12);
          accepted = true;
          if (decrease <= options.function_tolerance * (cost + 1e-12)) *converged = true;
          break;
        }
      }
      lambda *= 10.0;
    }
    if (!accepted) {
      *converged = true;  // no step decreases the cost: a (local) minimum
      break;
    }
    if (*converged) break;
  }
  return pose;
}

}  // namespace

RefinementResult refinePose(const Intrinsics& K, const Pose& initial, const std::vector<EllipseMatch>& objects,
                            const std::vector<PointMatch>& points, const RefinerOptions& options,
                            const std::optional<GravityPrior>& gravity) {
  RefinementResult result;
  result.pose = initial;
  result.fell_back = true;
  const auto fillResiduals = [&](RefinementResult& r) {
    r.object_residuals.clear();
    for (const EllipseMatch& m : objects) {
      const Projection p = project(m.ellipsoid, K, r.pose);
      const double scale = std::sqrt(m.observed.axes().prod());
      r.object_residuals.push_back(p && m.observed.isValid() ? wasserstein2(m.observed, p.ellipse) / scale : -1.0);
    }
    r.point_residuals.clear();
    for (const PointMatch& m : points) {
      const Eigen::Vector3d x = r.pose.transform(m.point);
      r.point_residuals.push_back(x(2) > 0 ? (K.project(x) - m.observed).norm() : -1.0);
    }
  };
  if (!K.isValid() || !initial.isValid()) {
    result.message = "invalid intrinsics or initial pose";
    fillResiduals(result);
    return result;
  }
  if (gravity && !gravity->isValid()) {
    result.message = "invalid gravity prior (zero or non-finite direction, or sigma <= 0)";
    fillResiduals(result);
    return result;
  }
  std::optional<UnitGravity> unit_gravity;
  if (gravity)
    unit_gravity = UnitGravity{gravity->up_in_map.normalized(), gravity->up_in_camera.normalized(),
                               gravity->sigma_deg * M_PI / 180.0};
  Problem problem{K, {}, {}, {}, points, options, unit_gravity ? &*unit_gravity : nullptr};
  for (const EllipseMatch& m : objects) {
    if (!m.observed.isValid() || !(std::isfinite(m.sigma) && m.sigma > 0) || !project(m.ellipsoid, K, initial))
      continue;
    problem.objects.push_back(&m);
    problem.prepared.emplace_back(m.ellipsoid);
    problem.object_scale.push_back(m.sigma * std::sqrt(m.observed.axes().prod()));
  }
  if (problem.objects.empty() && points.empty()) {
    result.message = "no usable correspondence (no object projects at the initial pose)";
    fillResiduals(result);
    return result;
  }
  double cost = 0.0;
  if (!problem.cost(initial, &cost)) {
    result.message = "cost not finite at the initial pose (a point behind the camera?)";
    fillResiduals(result);
    return result;
  }
  result.initial_cost = cost;
  if (options.backend == RefinerBackend::Ceres) {
    bool converged = false;
    const Pose refined = solveWithCeres(problem, initial, options, &result.iterations, &converged);
    double refined_cost = 0.0;
    // Ceres' cost is ours times 1/2; compare with ours, and never return a worse pose.
    if (refined.isValid() && problem.cost(refined, &refined_cost) && refined_cost <= cost) {
      result.pose = refined;
      result.final_cost = refined_cost;
      result.converged = converged;
      result.fell_back = false;
    } else {
      result.final_cost = cost;
      result.message = "the solver ended at a higher cost; returning the initial pose";
    }
    fillResiduals(result);
    return result;
  }
  result.pose = solveWithLevenbergMarquardt(problem, initial, options, &cost, &result.iterations, &result.converged);
  result.final_cost = cost;
  result.fell_back = false;
  fillResiduals(result);
  return result;
}

}  // namespace ellreloc
