#pragma once
/// \file few_object_poses.hpp
/// Camera poses from one or two ellipse-ellipsoid correspondences, using the ellipses' shapes
/// and not only their centres (P3P needs three centres).
///
/// Two pairs (as in Gaudilliere, Simon, Berger, "Perspective-2-Ellipsoid", RA-L 2020): the two
/// observed centres give the bearings of the ellipsoid centres; the ratio of the objects'
/// apparent sizes gives the direction of the segment between them in the camera, which fixes
/// the rotation up to an angle about that segment. That angle is swept; at each angle every
/// ellipsoid is placed along its bearing at the depth where its projection has the observed
/// size (the projected-centre offset removed), and the pose is scored by the normalised W2 of
/// both ellipses. The best local minima are refined with the Wasserstein refiner (10
/// constraints for 6 unknowns).
///
/// One pair and gravity (as in their "Perspective-1-Ellipsoid", IJCV 2023): gravity fixes the
/// tilt, the yaw about gravity is swept, the ellipsoid placed as above, and the best minima
/// refined with the gravity prior (5 + 2 constraints). An ellipsoid that is symmetric about
/// the vertical leaves its yaw unobservable: every yaw fits, so expect one of them.
///
/// Both return poses best first with their refined cost; an empty vector when no angle puts
/// the objects in front of the camera.

#include <optional>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/camera_envelope.hpp"
#include "ellreloc/pose/gravity_prior.hpp"
#include "ellreloc/pose/pose_region.hpp"
#include "ellreloc/pose/wasserstein_refiner.hpp"

namespace ellreloc {

struct FewObjectOptions {
  int angle_steps = 24;         ///< angles tried about the free axis (15 degrees apart)
  double axis_step_deg = 20.0;  ///< spacing of the directions tried for the segment between two objects
  int max_poses = 3;            ///< best local minima of the sweep that are refined and returned
  /// With gravity, a rotation of the two-object sweep whose gravity term alone costs more than
  /// the best rotation found at that angle is not placed: the same poses, a few times faster.
  bool skip_tilted = true;
  RefinerOptions refiner;
  /// Metres per unit of the ellipsoids' coordinates: refined poses within 1 cm and half a degree
  /// of each other are one. The relocalizer sets its map's (ObjectMap::unit_metres). A unit that
  /// is not a positive length gives no pose.
  double unit_metres = 1.0;
};

/// Poses from two ellipse-ellipsoid correspondences (distinct ellipsoid centres), optionally
/// constrained by gravity. Each pose's cost is the refiner's robust cost there (normalised W2,
/// plus gravity). With a camera `envelope`, every pose returned lies within it, and the sweep
/// places only rotations within its tilt and roll bounds, so that those outside are neither
/// refined nor take the places of the `max_poses` minima of those within. (Heights are checked
/// after the refinement only: a placement before it can be tens of centimetres off.) A pose
/// `region` bounds them the same way: rotations beyond its angle are not placed, and every pose
/// returned lies within it. An invalid envelope or region gives no pose.
std::vector<ScoredPose> posesFromTwoObjects(const Intrinsics& K, const EllipseMatch& a, const EllipseMatch& b,
                                            const std::optional<GravityPrior>& gravity = std::nullopt,
                                            const FewObjectOptions& options = {},
                                            const std::optional<CameraEnvelope>& envelope = std::nullopt,
                                            const std::optional<PoseRegion>& region = std::nullopt);

/// Poses from one ellipse-ellipsoid correspondence and gravity.
std::vector<ScoredPose> posesFromOneObject(const Intrinsics& K, const EllipseMatch& a, const GravityPrior& gravity,
                                           const FewObjectOptions& options = {});

/// The translation that puts `match.ellipsoid`, seen with rotation R_cw, where its projection
/// has the observed ellipse's centre and size (depth from the size, bearing corrected for
/// the offset between the projected ellipse's centre and the projected centre). nullopt when
/// the ellipsoid cannot be placed in front of the camera.
std::optional<Eigen::Vector3d> placeObject(const Intrinsics& K, const Eigen::Matrix3d& R_cw, const EllipseMatch& match);

}  // namespace ellreloc
