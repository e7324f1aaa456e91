#include "ellreloc/mapping/box_ellipsoid_builder.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <cmath>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/core/statistics.hpp"
#include "ellreloc/mapping/ellipsoid_builder.hpp"

namespace ellreloc {
namespace {

/// W2 between the box-inscribed ellipse and the projection of the ellipsoid (centre c,
/// semi-axes exp(s), rotation base * angle-axis w), divided by sqrt(a b) of the observed
/// ellipse so that small and large boxes weigh alike. The 6-vector r has |r|^2 = W2^2
/// (distances.hpp).
struct BoxW2Cost {
  Eigen::Matrix<double, 3, 4> P;  // K [R | t]
  Pose pose;
  Ellipse observed;
  double scale;
  Eigen::Matrix3d base;

  // Flattened: every Jet operation inlined. Left to itself GCC calls Eigen's 9-vector kernels
  // of the Jets out of line, which cost half of a box map's time. The constants (P, base,
  // scale) stay plain numbers (projectDualQuadric says why).
  template <typename T>
  [[gnu::flatten]] bool operator()(const T* c, const T* s, const T* w, T* residual) const {
    T R_data[9];
    ceres::AngleAxisToRotationMatrix(w, ceres::ColumnMajorAdapter3x3(R_data));
    const Eigen::Matrix<T, 3, 3> R = base * Eigen::Map<const Eigen::Matrix<T, 3, 3>>(R_data);
    const Eigen::Matrix<T, 3, 1> centre(c[0], c[1], c[2]);
    Eigen::Matrix<T, 3, 1> axes2;
    for (int k = 0; k < 3; ++k) axes2(k) = exp(2.0 * s[k]);
    const Eigen::Matrix<T, 3, 3> M = R * axes2.asDiagonal() * R.transpose();
    T near, far;
    depthRange<T>(pose.rotation().cast<T>(), pose.translation().cast<T>(), centre, M, &near, &far);
    if (!(near > T(0.0))) return false;  // the ellipsoid must stay in front of the camera
    Eigen::Matrix<T, 4, 4> Q;
    Q.template topLeftCorner<3, 3>() = M - centre * centre.transpose();
    Q.template topRightCorner<3, 1>() = -centre;
    Q.template bottomLeftCorner<1, 3>() = -centre.transpose();
    Q(3, 3) = T(-1.0);
    const Mat3<T> C = projectDualQuadric<double, T>(P, Q);
    Vec2<T> mean;
    Mat2<T> cov;
    gaussianFromDualConic<T>(C, &mean, &cov);
    wasserstein2Residual<T>(observed.center().cast<T>(), observed.covariance().cast<T>(), mean, cov, residual);
    for (int k = 0; k < 6; ++k) residual[k] /= scale;
    return true;
  }
};

/// The size prior (BoxSizePrior): the sorted log semi-axes against the sorted typical ones.
struct SizePriorCost {
  Eigen::Vector3d log_typical;  // sorted ascending
  double sigma;

  template <typename T>
  bool operator()(const T* s, T* residual) const {
    T v[3] = {s[0], s[1], s[2]};
    // Sort three values ascending (compare-swap; Jets compare by their value).
    if (v[1] < v[0]) std::swap(v[0], v[1]);
    if (v[2] < v[1]) std::swap(v[1], v[2]);
    if (v[1] < v[0]) std::swap(v[0], v[1]);
    for (int k = 0; k < 3; ++k) residual[k] = (v[k] - T(log_typical(k))) / T(sigma);
    return true;
  }
};

/// At most `n` views, evenly spread over the sequence (all of them when there are fewer).
std::vector<BoxView> spread(const std::vector<BoxView>& views, size_t n) {
  if (views.size() <= n || n == 0) return views;
  std::vector<BoxView> out;
  for (size_t k = 0; k < n; ++k) out.push_back(views[k * (views.size() - 1) / (n - 1)]);
  return out;
}

/// The Ceres fit of the 9-DoF ellipsoid (or 7 when upright) from `centre` and a sphere of
/// `radius`, with the size prior; false (and `out` says why) when it cannot be made.
bool fitEllipsoid(const Intrinsics& K, const std::vector<BoxView>& views, const BoxEllipsoidOptions& options,
                  const BoxSizePrior& prior, const Eigen::Vector3d& centre, double radius, BoxEllipsoidResult* out) {
  // Semi-axis bounds from the prior; the initial radius within them.
  Eigen::Vector3d typical = prior.typical_semi_axes;
  std::sort(typical.data(), typical.data() + 3);
  double lo = 1e-3, hi = 1e3;
  if (options.use_size_prior) {
    lo = std::max(prior.min_axis, typical(0) / prior.range_factor);
    hi = std::max(lo * 2.0, std::min(prior.max_axis, typical(2) * prior.range_factor));
  }
  double c[3] = {centre.x(), centre.y(), centre.z()};
  const double log_r = std::log(std::clamp(radius, lo, hi));
  double s[3] = {log_r, log_r, log_r};
  double w[3] = {0.0, 0.0, 0.0};
  const Eigen::Matrix3d base = options.up ? groundBasis(*options.up) : Eigen::Matrix3d::Identity();

  ceres::Problem problem;
  for (const BoxView& v : views) {
    const auto e = Ellipse::inscribedInBox(v.box);
    if (!e) continue;
    auto* cost = new BoxW2Cost{projectionMatrix(K, v.pose), v.pose, *e, std::sqrt(e->axes().prod()), base};
    double probe[6];
    const double* params[3] = {c, s, w};
    if (!(*cost)(params[0], params[1], params[2], probe)) {  // a camera inside the start sphere
      delete cost;
      continue;
    }
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BoxW2Cost, 6, 3, 3, 3>(cost),
                             new ceres::CauchyLoss(options.loss_scale), c, s, w);
  }
  if (problem.NumResidualBlocks() < static_cast<int>(std::max<size_t>(options.min_views, 2))) {
    out->status = BoxEllipsoidStatus::TooFewViews;
    out->reason = std::to_string(problem.NumResidualBlocks()) + " views see the object from outside";
    return false;
  }
  if (options.use_size_prior) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<SizePriorCost, 3, 3>(
                                 new SizePriorCost{typical.array().log().matrix(), prior.sigma_log}),
                             nullptr, s);
    for (int k = 0; k < 3; ++k) {
      problem.SetParameterLowerBound(s, k, std::log(lo));
      problem.SetParameterUpperBound(s, k, std::log(hi));
    }
  }
  if (options.up) problem.SetManifold(w, new ceres::SubsetManifold(3, {0, 1}));  // yaw about up only
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);

  double R_data[9];
  ceres::AngleAxisToRotationMatrix(w, ceres::ColumnMajorAdapter3x3(R_data));
  const Eigen::Matrix3d R = nearestRotation(base * Eigen::Map<const Eigen::Matrix3d>(R_data));
  out->ellipsoid =
      Ellipsoid(Eigen::Vector3d(c[0], c[1], c[2]), Eigen::Vector3d(std::exp(s[0]), std::exp(s[1]), std::exp(s[2])), R);
  if (!out->ellipsoid.isValid()) {
    out->status = BoxEllipsoidStatus::InvalidInput;
    out->reason = "refinement diverged";
    return false;
  }
  return true;
}

/// Where the object stands when its rays barely diverge: on each view's ray through the box
/// centre, at the depth where an object of the category's typical size fills the box; the
/// mean over the views (the fit then weighs the little parallax there is against the prior).
std::optional<Eigen::Vector3d> centreAtTypicalSize(const Intrinsics& K, const std::vector<BoxView>& views,
                                                   const BoxSizePrior& prior) {
  const double typical_radius = prior.typical_semi_axes.mean();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const BoxView& v : views) {
    const Eigen::Vector3d b = K.bearing(Eigen::Vector2d(0.5 * (v.box.x1 + v.box.x2), 0.5 * (v.box.y1 + v.box.y2)));
    const double radius_per_depth = boxRadiusPerDepth(K, v.box);
    if (!(b.z() > 0.0) || !(radius_per_depth > 0.0)) return std::nullopt;
    const double depth = typical_radius / radius_per_depth;
    sum += v.pose.center() + v.pose.rotation().transpose() * (b / b.z() * depth);
  }
  const Eigen::Vector3d centre = sum / static_cast<double>(views.size());
  if (!centre.allFinite()) return std::nullopt;
  return centre;
}

/// The widest angle between two rays through the views' box centres, degrees.
double baselineDeg(const Intrinsics& K, const std::vector<BoxView>& views) {
  std::vector<Eigen::Vector3d> rays;
  for (const BoxView& v : views)
    rays.push_back(v.pose.rotation().transpose() *
                   K.bearing(Eigen::Vector2d(0.5 * (v.box.x1 + v.box.x2), 0.5 * (v.box.y1 + v.box.y2))));
  double min_cos = 1.0;
  for (size_t i = 0; i < rays.size(); ++i)
    for (size_t j = i + 1; j < rays.size(); ++j) min_cos = std::min(min_cos, rays[i].dot(rays[j]));
  return std::acos(std::clamp(min_cos, -1.0, 1.0)) * 180.0 / M_PI;
}

/// The object's centre from its views: the point nearest to the rays through the box centres
/// when they span at least `min_baseline_deg`, else (given a prior) on them where the category's
/// typical size fills the boxes, which `*from_size` then says.
std::optional<Eigen::Vector3d> centreFromViews(const Intrinsics& K, const std::vector<BoxView>& views,
                                               double baseline_deg, double min_baseline_deg, const BoxSizePrior* prior,
                                               bool* from_size) {
  std::optional<Eigen::Vector3d> centre =
      baseline_deg < min_baseline_deg ? std::nullopt : triangulateBoxCentres(K, views);
  *from_size = false;
  if (!centre && prior) {
    centre = centreAtTypicalSize(K, views, *prior);
    *from_size = centre.has_value();
  }
  return centre;
}

}  // namespace

const char* toString(BoxEllipsoidStatus status) {
  switch (status) {
    case BoxEllipsoidStatus::Ok:
      return "ok";
    case BoxEllipsoidStatus::TooFewViews:
      return "too few views";
    case BoxEllipsoidStatus::NoBaseline:
      return "no baseline";
    case BoxEllipsoidStatus::BehindCamera:
      return "behind camera";
    case BoxEllipsoidStatus::PoorFit:
      return "poor fit";
    case BoxEllipsoidStatus::InvalidInput:
      return "invalid input";
  }
  return "unknown";
}

std::optional<Eigen::Vector3d> triangulateBoxCentres(const Intrinsics& K, const std::vector<BoxView>& views) {
  if (!K.isValid() || views.size() < 2) return std::nullopt;
  // Minimise sum_i |(I - d_i d_i^T)(x - o_i)|^2 over x: the point nearest to all rays.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const BoxView& v : views) {
    if (!v.pose.isValid() || !v.box.isValid()) return std::nullopt;
    const Eigen::Vector2d uv(0.5 * (v.box.x1 + v.box.x2), 0.5 * (v.box.y1 + v.box.y2));
    const Eigen::Vector3d d = v.pose.rotation().transpose() * K.bearing(uv);
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * v.pose.center();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(A);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()(0) > 1e-6 * eig.eigenvalues()(2))) return std::nullopt;
  const Eigen::Vector3d x = A.ldlt().solve(b);
  if (!x.allFinite()) return std::nullopt;
  return x;
}

BoxEllipsoidResult buildEllipsoidFromBoxes(const Intrinsics& K, const std::vector<BoxView>& all_views,
                                           const BoxEllipsoidOptions& options, const BoxSizePrior& prior) {
  BoxEllipsoidResult out;
  if (!K.isValid()) {
    out.reason = "invalid intrinsics";
    return out;
  }
  if (!(options.loss_scale > 0.0) || !std::isfinite(options.loss_scale)) {
    out.reason = "loss_scale is not a positive number";
    return out;
  }
  std::vector<BoxView> valid, inside;
  for (const BoxView& v : all_views) {
    if (!v.pose.isValid() || !v.box.isValid() || !(v.box.area() > 1.0)) continue;
    valid.push_back(v);
    if (!(v.cut ? *v.cut : v.box.nearImageBorder(K.width, K.height, options.border_px))) inside.push_back(v);
  }
  const std::vector<BoxView> views = spread(inside.size() >= options.min_views ? inside : valid, options.max_views);
  out.views_used = static_cast<int>(views.size());
  if (views.size() < std::max<size_t>(options.min_views, 2)) {
    out.status = BoxEllipsoidStatus::TooFewViews;
    out.reason = std::to_string(views.size()) + " valid views";
    return out;
  }
  out.baseline_deg = baselineDeg(K, views);
  const std::optional<Eigen::Vector3d> centre =
      centreFromViews(K, views, out.baseline_deg, options.min_baseline_deg, options.use_size_prior ? &prior : nullptr,
                      &out.depth_from_size);
  if (!centre) {
    out.status = BoxEllipsoidStatus::NoBaseline;
    out.reason = "rays span " + std::to_string(out.baseline_deg) + " deg";
    return out;
  }
  // Initial semi-axes: a sphere whose size matches the boxes at the triangulated depth.
  std::vector<double> radii;
  for (const BoxView& v : views) {
    const double z = v.pose.transform(*centre).z();
    if (!(z > 0.0)) {
      out.status = BoxEllipsoidStatus::BehindCamera;
      out.reason = "triangulated centre behind a camera";
      return out;
    }
    radii.push_back(boxRadiusPerDepth(K, v.box) * z);
  }
  if (!fitEllipsoid(K, views, options, prior, *centre, median(radii), &out)) return out;
  std::vector<double> ious;
  for (const BoxView& v : views) {
    const Projection p = project(out.ellipsoid, K, v.pose);
    ious.push_back(p ? boxIoU(p.ellipse.boundingBox(), v.box) : 0.0);
  }
  out.median_iou = median(ious);
  if (out.median_iou < options.min_median_iou) {
    out.status = BoxEllipsoidStatus::PoorFit;
    out.reason = "median reprojection IoU " + std::to_string(out.median_iou);
    return out;
  }
  out.status = BoxEllipsoidStatus::Ok;
  return out;
}

std::vector<Box> predictedBoxes(const Intrinsics& K, const std::vector<BoxView>& views, const BoxSizePrior& prior,
                                double min_baseline_deg, const Pose& pose) {
  std::vector<Box> out;
  if (!K.isValid() || views.empty() || !pose.isValid()) return out;
  for (const BoxView& v : views)
    if (!v.pose.isValid() || !v.box.isValid()) return out;
  bool from_size = false;
  const std::optional<Eigen::Vector3d> centre =
      centreFromViews(K, views, baselineDeg(K, views), min_baseline_deg, &prior, &from_size);
  if (!centre) return out;
  const BoxView& last = views.back();
  // Placed by the typical size, the object may be as much nearer or farther along the last
  // view's ray as real objects differ from their category's typical size (the prior's range),
  // in steps of sqrt(2).
  std::vector<Eigen::Vector3d> centres{*centre};
  const int steps = from_size ? static_cast<int>(std::floor(2.0 * std::log2(std::max(1.0, prior.range_factor)))) : 0;
  for (int k = -steps; k <= steps; ++k)
    if (k != 0) centres.push_back(last.pose.center() + std::pow(2.0, 0.5 * k) * (*centre - last.pose.center()));
  const Eigen::Vector2d box_centre(0.5 * (last.box.x1 + last.box.x2), 0.5 * (last.box.y1 + last.box.y2));
  for (const Eigen::Vector3d& x : centres) {
    const Eigen::Vector3d then = last.pose.transform(x), now = pose.transform(x);
    if (!(then.z() > 0.0) || !(now.z() > 0.0)) continue;
    // The last box, moved as the centre's image moves and scaled by the change of depth; the
    // offset of the box from that image is kept, so an unmoved camera expects the last box.
    const double scale = then.z() / now.z();
    const Eigen::Vector2d c = K.project(now) + scale * (box_centre - K.project(then));
    const Eigen::Vector2d half(0.5 * scale * last.box.width(), 0.5 * scale * last.box.height());
    const Box box(c.x() - half.x(), c.y() - half.y(), c.x() + half.x(), c.y() + half.y());
    if (box.isValid()) out.push_back(box);
  }
  return out;
}

}  // namespace ellreloc
