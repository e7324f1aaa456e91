#pragma once
/// \file pose_region.hpp
/// Where a host knows the camera to be, roughly: near the last pose it tracked. A SLAM system
/// that lost tracking a moment ago (motion blur, a covered lens) knows that the camera has moved
/// at most so far and turned at most so much since; look-alike objects elsewhere in the map (a
/// second desk with the same monitor, keyboard and books) then cannot give a hypothesis. Poses
/// outside the region are never hypotheses, as with the camera envelope (a gate, not a cost). A
/// kidnapped robot has no region: leave it out.

#include <Eigen/Core>
#include <cmath>

#include "ellreloc/core/pose.hpp"

namespace ellreloc {

struct PoseRegion {
  Pose pose;                        ///< world->camera: the last pose the host tracked
  /// The camera centre lies within this distance of pose.center(), in the map's units (metres in
  /// a metric map).
  double radius_m = 1.0;
  double max_rotation_deg = 180.0;  ///< and its rotation within this angle of pose's (180: any)

  /// A valid pose, a positive finite radius and an angle in (0, 180].
  bool isValid() const {
    return pose.isValid() && std::isfinite(radius_m) && radius_m > 0.0 && max_rotation_deg > 0.0 &&
           max_rotation_deg <= 180.0;
  }

  /// The test prepared once for the many poses of a search: the centre, the squared radius and
  /// the angle as a bound on trace(R R_region^T) = 1 + 2 cos(angle), so that a pose costs a few
  /// dot products and no arc cosine.
  struct Prepared {
    Eigen::Vector3d centre;
    Eigen::Matrix3d rotation;  // world->camera of the region's pose
    double max_squared_distance;
    double min_trace;  // below -1 without a rotation bound
    bool admits(const Pose& p) const {
      return (p.center() - centre).squaredNorm() <= max_squared_distance && admitsRotation(p.rotation());
    }
    /// The angle bound alone, for a world->camera rotation whose translation is not known yet.
    bool admitsRotation(const Eigen::Matrix3d& R_cw) const {
      return min_trace < -1.0 || R_cw.cwiseProduct(rotation).sum() >= min_trace;
    }
  };
  Prepared prepared() const {
    const double min_trace = max_rotation_deg >= 180.0 ? -2.0 : 1.0 + 2.0 * std::cos(max_rotation_deg * M_PI / 180.0);
    return {pose.center(), pose.rotation(), radius_m * radius_m, min_trace};
  }

  /// The world->camera pose `p` lies within the region.
  bool admits(const Pose& p) const { return prepared().admits(p); }
};

}  // namespace ellreloc
