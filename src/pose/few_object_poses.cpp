#include "ellreloc/pose/few_object_poses.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/projection.hpp"

namespace ellreloc {

namespace {

/// The dual conic of the image of an ellipsoid given in the camera frame: centre x, shape
/// matrix M = R diag(a^2) R^T turned into the camera. It is K (M - x x^T) K^T (P Q* P^T for
/// P = K [R | t], written without the world), an ellipse when the ellipsoid lies strictly in
/// front of the principal plane (x_z > 0 and M_zz < x_z^2, as projectPrepared tells it), else
/// nullopt. The sweeps place each object at many depths for one rotation: M is computed once
/// for all of them.
std::optional<Eigen::Matrix3d> dualConicInCameraFrame(const Eigen::Matrix3d& M, const Eigen::Vector3d& x,
                                                      const Intrinsics& K) {
  if (!x.allFinite()) return std::nullopt;
  const Eigen::Matrix3d N = M - x * x.transpose();
  if (!(x(2) > 0.0 && N(2, 2) < 0.0)) return std::nullopt;
  // K N K^T with K's zeros skipped.
  const double u = K.fx * N(0, 2) + K.cx * N(2, 2), v = K.fy * N(1, 2) + K.cy * N(2, 2);
  Eigen::Matrix3d C;
  C(0, 0) = K.fx * (K.fx * N(0, 0) + K.cx * N(0, 2)) + K.cx * u;
  C(1, 1) = K.fy * (K.fy * N(1, 1) + K.cy * N(1, 2)) + K.cy * v;
  C(0, 1) = C(1, 0) = K.fx * (K.fy * N(0, 1) + K.cy * N(0, 2)) + K.cx * v;
  C(0, 2) = C(2, 0) = u;
  C(1, 2) = C(2, 1) = v;
  C(2, 2) = N(2, 2);
  return C;
}

std::optional<Ellipse> imageInCameraFrame(const Eigen::Matrix3d& M, const Eigen::Vector3d& x, const Intrinsics& K) {
  const std::optional<Eigen::Matrix3d> C = dualConicInCameraFrame(M, x, K);
  return C ? Ellipse::fromDualConic(*C) : std::nullopt;
}

/// imageInCameraFrame's centre and size (Ellipse::centreAndSizeFromDualConic), nullopt exactly
/// where it has no ellipse.
std::optional<Ellipse::CentreAndSize> imageCentreAndSize(const Eigen::Matrix3d& M, const Eigen::Vector3d& x,
                                                         const Intrinsics& K) {
  const std::optional<Eigen::Matrix3d> C = dualConicInCameraFrame(M, x, K);
  return C ? Ellipse::centreAndSizeFromDualConic(*C) : std::nullopt;
}

/// placeObject for a prepared, valid ellipsoid and a rotation; `M`: its shape matrix in the
/// camera, R_cw prepared.shape R_cw^T.
std::optional<Eigen::Vector3d> placePrepared(const Intrinsics& K, const Eigen::Matrix3d& R_cw, const Ellipse& observed,
                                             const ProjectableEllipsoid& prepared, const Eigen::Matrix3d& M) {
  const Ellipsoid& e = prepared.ellipsoid;
  const double observed_size = std::sqrt(observed.axes().prod());
  Eigen::Vector3d bearing = K.bearing(observed.center());
  // First depth from the silhouette seen along the bearing (orthographic): its radius
  // det(S)^(1/4), S the camera-frame shape matrix restricted to the plane across the bearing.
  const Eigen::Vector3d u = bearing.unitOrthogonal(), v = bearing.cross(u);
  Eigen::Matrix2d S;
  S << u.dot(M * u), u.dot(M * v), v.dot(M * u), v.dot(M * v);
  const double focal = std::sqrt(K.fx * K.fy);
  double depth = focal * std::sqrt(std::sqrt(std::max(S.determinant(), 0.0))) / observed_size;
  depth = std::max(depth, 1.01 * e.axes().maxCoeff());  // the camera stays outside
  // Perspective: the image size goes as 1 / depth near the answer, and the centre of the
  // projected ellipse is not the projection of the centre; a few fixed-point steps fix both.
  // The ellipsoid's centre is at depth x bearing in the camera.
  for (int iteration = 0; iteration < 4; ++iteration) {
    const std::optional<Ellipse::CentreAndSize> image = imageCentreAndSize(M, depth * bearing, K);
    if (!image) {
      depth *= 2.0;  // too close: the ellipsoid reaches behind the principal plane
      continue;
    }
    const Eigen::Vector2d offset = image->centre - K.project(depth * bearing);
    depth *= image->size / observed_size;
    bearing = K.bearing(observed.center() - offset);
  }
  const Eigen::Vector3d t = depth * bearing - R_cw * e.center();
  if (!t.allFinite() || !imageCentreAndSize(M, depth * bearing, K)) return std::nullopt;
  return t;
}

/// An ellipsoid's shape matrix turned into the camera of rotation R_cw: R_cw M R_cw^T.
Eigen::Matrix3d shapeInCamera(const Eigen::Matrix3d& R_cw, const ProjectableEllipsoid& prepared) {
  return R_cw * prepared.shape * R_cw.transpose();
}

}  // namespace

std::optional<Eigen::Vector3d> placeObject(const Intrinsics& K, const Eigen::Matrix3d& R_cw,
                                           const EllipseMatch& match) {
  if (!K.isValid() || !match.observed.isValid() || !match.ellipsoid.isValid() || !isRotation(R_cw)) return std::nullopt;
  const ProjectableEllipsoid prepared(match.ellipsoid);
  return placePrepared(K, R_cw, match.observed, prepared, shapeInCamera(R_cw, prepared));
}

namespace {

/// The gravity term of sweepCost: the squared tilt error in units of the prior's sigma.
double gravityCost(const GravityPrior& gravity, const Eigen::Matrix3d& R_cw) {
  const double angle = gravity.errorDeg(Pose(R_cw, Eigen::Vector3d::Zero())) / gravity.sigma_deg;
  return angle * angle;
}

/// The refiner's object cost (its robust loss of the normalised W2^2) plus the gravity term: the
/// sweep ranks angles by what the refinement will minimise. `prepared`: the matches' ellipsoids,
/// `shapes`: their shape matrices in the camera at this pose's rotation.
double sweepCost(const Intrinsics& K, const Pose& pose, const std::vector<EllipseMatch>& matches,
                 const std::vector<ProjectableEllipsoid>& prepared, const std::vector<Eigen::Matrix3d>& shapes,
                 const std::optional<GravityPrior>& gravity, const RefinerOptions& opt) {
  double total = 0.0;
  for (size_t i = 0; i < matches.size(); ++i) {
    const EllipseMatch& m = matches[i];
    const std::optional<Ellipse> image =
        imageInCameraFrame(shapes[i], pose.transform(prepared[i].ellipsoid.center()), K);
    if (!image) return std::numeric_limits<double>::infinity();
    const double s = wasserstein2Squared(m.observed, *image) / m.observed.axes().prod();
    total += robustLoss(opt.object_loss, opt.object_loss_scale, s);
  }
  if (gravity) total += gravityCost(*gravity, pose.rotation());
  return std::isfinite(total) ? total : std::numeric_limits<double>::infinity();
}

/// Places every object at rotation R_cw; the translation is the mean of their placements.
/// `shapes` receives the objects' shape matrices in the camera.
std::optional<Pose> placeAll(const Intrinsics& K, const Eigen::Matrix3d& R_cw, const std::vector<EllipseMatch>& matches,
                             const std::vector<ProjectableEllipsoid>& prepared, std::vector<Eigen::Matrix3d>* shapes) {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  shapes->resize(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    (*shapes)[i] = shapeInCamera(R_cw, prepared[i]);
    const auto ti = placePrepared(K, R_cw, matches[i].observed, prepared[i], (*shapes)[i]);
    if (!ti) return std::nullopt;
    t += *ti / static_cast<double>(matches.size());
  }
  return Pose(R_cw, t);
}

std::vector<ProjectableEllipsoid> prepare(const std::vector<EllipseMatch>& matches) {
  std::vector<ProjectableEllipsoid> out;
  for (const EllipseMatch& m : matches) out.emplace_back(m.ellipsoid);
  return out;
}

/// Where the poses of a sweep must lie: a camera envelope's heights, tilts and rolls and a pose
/// region's distance and angle, each when given.
struct SweepBounds {
  std::optional<CameraEnvelope::Prepared> envelope;
  std::optional<PoseRegion::Prepared> region;
  bool admitsRotation(const Eigen::Matrix3d& R_cw) const {
    return (!envelope || envelope->admitsRotation(R_cw)) && (!region || region->admitsRotation(R_cw));
  }
  bool admits(const Pose& pose) const {
    return (!envelope || envelope->admits(pose)) && (!region || region->admits(pose));
  }
};

/// Sweeps poseAt(angle) (a ScoredPose with the sweep cost, or nullopt) over a full turn,
/// refines the best local minima of the cost and returns them, best first; with `bounds`, only
/// those the refinement leaves within them.
template <typename PoseAt>
std::vector<ScoredPose> sweepAndRefine(const Intrinsics& K, const std::vector<EllipseMatch>& matches,
                                       const std::optional<GravityPrior>& gravity, const FewObjectOptions& opt,
                                       const SweepBounds& bounds, PoseAt poseAt) {
  const int steps = std::max(4, opt.angle_steps);
  std::vector<double> cost(static_cast<size_t>(steps), std::numeric_limits<double>::infinity());
  std::vector<Pose> pose(static_cast<size_t>(steps));
  for (int k = 0; k < steps; ++k) {
    const std::optional<ScoredPose> p = poseAt(2.0 * M_PI * k / steps);
    if (!p) continue;
    pose[k] = p->pose;
    cost[k] = p->cost;
  }
  std::vector<int> minima;
  for (int k = 0; k < steps; ++k) {
    const double prev = cost[(k + steps - 1) % steps], next = cost[(k + 1) % steps];
    if (std::isfinite(cost[k]) && cost[k] <= prev && cost[k] < next) minima.push_back(k);
  }
  std::sort(minima.begin(), minima.end(), [&](int x, int y) { return cost[x] < cost[y]; });
  if (static_cast<int>(minima.size()) > opt.max_poses) minima.resize(static_cast<size_t>(std::max(0, opt.max_poses)));
  std::vector<ScoredPose> out;
  for (int k : minima) {
    const RefinementResult r = refinePose(K, pose[k], matches, {}, opt.refiner, gravity);
    const bool duplicate = std::any_of(out.begin(), out.end(), [&](const ScoredPose& p) {
      return (p.pose.center() - r.pose.center()).norm() < 0.01 / opt.unit_metres &&
             rotationErrorDeg(p.pose.rotation(), r.pose.rotation()) < 0.5;
    });
    if (!duplicate && r.pose.isValid() && bounds.admits(r.pose))
      out.push_back({r.pose, r.fell_back ? cost[k] : r.final_cost});
  }
  std::sort(out.begin(), out.end(), [](const ScoredPose& x, const ScoredPose& y) { return x.cost < y.cost; });
  return out;
}

bool usable(const Intrinsics& K, const EllipseMatch& m) {
  return K.isValid() && m.observed.isValid() && m.ellipsoid.isValid();
}

bool validUnit(const FewObjectOptions& options) {
  return options.unit_metres > 0.0 && std::isfinite(options.unit_metres);
}

}  // namespace

std::vector<ScoredPose> posesFromTwoObjects(const Intrinsics& K, const EllipseMatch& a, const EllipseMatch& b,
                                            const std::optional<GravityPrior>& gravity, const FewObjectOptions& options,
                                            const std::optional<CameraEnvelope>& envelope,
                                            const std::optional<PoseRegion>& region) {
  if (!usable(K, a) || !usable(K, b) || !validUnit(options) || (gravity && !gravity->isValid()) ||
      (envelope && !envelope->isValid()) || (region && !region->isValid()))
    return {};
  SweepBounds bounds;
  if (envelope) bounds.envelope = envelope->prepared();
  if (region) bounds.region = region->prepared();
  const Eigen::Vector3d world_axis = b.ellipsoid.center() - a.ellipsoid.center();
  if (!(world_axis.norm() > 1e-9)) return {};
  // The segment between the centres lies, in the camera, in the plane of the two bearings,
  // between -bearing_a (b at depth 0) and bearing_b (a at depth 0); where depends on the
  // ratio of the depths. The ratio of (object radius / image radius) guesses it, but
  // elongated objects mislead it, and when the bearings are close a small error in the ratio
  // turns the segment far: directions across the whole arc are tried as well.
  const Eigen::Vector3d bearing_a = K.bearing(a.observed.center()), bearing_b = K.bearing(b.observed.center());
  const auto depthScale = [&](const EllipseMatch& m) {
    return std::cbrt(m.ellipsoid.axes().prod()) / std::sqrt(m.observed.axes().prod());
  };
  std::vector<Eigen::Vector3d> camera_axes{(depthScale(b) * bearing_b - depthScale(a) * bearing_a).normalized()};
  const Eigen::Vector3d normal = bearing_a.cross(bearing_b);
  if (normal.norm() > 1e-9) {
    const Eigen::Vector3d in_plane = normal.normalized().cross(bearing_a);  // from -bearing_a towards bearing_b
    const double arc = M_PI - std::acos(std::clamp(bearing_a.dot(bearing_b), -1.0, 1.0));
    const int n = std::max(1, static_cast<int>(std::ceil(arc / (options.axis_step_deg * M_PI / 180.0))));
    for (int i = 0; i < n; ++i) {
      const double s = arc * (i + 0.5) / n;
      camera_axes.push_back(std::cos(s) * -bearing_a + std::sin(s) * in_plane);
    }
  }
  // For each: every rotation with R world_axis = camera_axis is an alignment followed by a
  // turn about the world axis; at each angle, the best of the axes counts.
  const Eigen::Vector3d w = world_axis.normalized();
  std::vector<Eigen::Matrix3d> aligns;
  for (const Eigen::Vector3d& c : camera_axes)
    if (c.allFinite()) aligns.push_back(Eigen::Quaterniond::FromTwoVectors(w, c).toRotationMatrix());
  const std::vector<EllipseMatch> matches{a, b};
  const std::vector<ProjectableEllipsoid> prepared = prepare(matches);
  std::vector<Eigen::Matrix3d> rotations(aligns.size());
  std::vector<double> tilt_cost(aligns.size(), 0.0);
  std::vector<size_t> order(aligns.size());
  std::vector<Eigen::Matrix3d> shapes;
  return sweepAndRefine(K, matches, gravity, options, bounds, [&](double angle) -> std::optional<ScoredPose> {
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle, w).toRotationMatrix();
    for (size_t i = 0; i < aligns.size(); ++i) {
      rotations[i] = aligns[i] * turn;
      if (gravity && options.skip_tilted) tilt_cost[i] = gravityCost(*gravity, rotations[i]);
    }
    // The cost of the first of the rotations that cost least. The objects' terms are not
    // negative, so a rotation's gravity term alone bounds its cost from below: with gravity,
    // the rotations are tried from the most level one, and one whose tilt already costs more
    // than the best found is not placed (most of them, the prior being a few degrees wide).
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    if (gravity && options.skip_tilted)
      std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return tilt_cost[x] < tilt_cost[y]; });
    std::optional<ScoredPose> best;
    size_t best_index = 0;
    for (const size_t i : order) {
      if (best && (tilt_cost[i] > best->cost || (tilt_cost[i] == best->cost && i > best_index))) continue;
      // Rotations outside the envelope's tilts and rolls, or the region's angle, are not placed:
      // their minima would take the places of those within, for poses that mostly refine to
      // outside it.
      if (!bounds.admitsRotation(rotations[i])) continue;
      const std::optional<Pose> pose = placeAll(K, rotations[i], matches, prepared, &shapes);
      if (!pose) continue;
      const double cost = sweepCost(K, *pose, matches, prepared, shapes, gravity, options.refiner);
      if (!best || cost < best->cost || (cost == best->cost && i < best_index))
        best = ScoredPose{*pose, cost}, best_index = i;
    }
    return best;
  });
}

std::vector<ScoredPose> posesFromOneObject(const Intrinsics& K, const EllipseMatch& a, const GravityPrior& gravity,
                                           const FewObjectOptions& options) {
  if (!usable(K, a) || !validUnit(options) || !gravity.isValid()) return {};
  // Every rotation with R up_map = up_camera: align, then turn about the map's up (the yaw).
  const Eigen::Vector3d up = gravity.up_in_map.normalized();
  const Eigen::Matrix3d align =
      Eigen::Quaterniond::FromTwoVectors(up, gravity.up_in_camera.normalized()).toRotationMatrix();
  const std::vector<EllipseMatch> matches{a};
  const std::vector<ProjectableEllipsoid> prepared = prepare(matches);
  std::vector<Eigen::Matrix3d> shapes;
  return sweepAndRefine(K, matches, gravity, options, SweepBounds{}, [&](double yaw) -> std::optional<ScoredPose> {
    const std::optional<Pose> pose =
        placeAll(K, align * Eigen::AngleAxisd(yaw, up).toRotationMatrix(), matches, prepared, &shapes);
    if (!pose) return std::nullopt;
    return ScoredPose{*pose, sweepCost(K, *pose, matches, prepared, shapes, gravity, options.refiner)};
  });
}

}  // namespace ellreloc
