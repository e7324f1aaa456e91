#pragma once
/// \file box_ellipsoid_builder.hpp
/// Monocular object mapping from boxes: an ellipsoid from three or more detection boxes of one
/// object seen from known camera poses (as OA-SLAM and QuadricSLAM users have them). The centre
/// is triangulated from the rays through the box centres (or, when the rays barely diverge,
/// placed on them where the category's typical size fills the boxes), the semi-axes start from
/// the box sizes at that depth, and the 9-DoF ellipsoid (centre, semi-axes, rotation) is refined by
/// minimising the squared Wasserstein distance between each box-inscribed ellipse and the
/// ellipsoid's projection (Ceres). A size prior keeps an axis the boxes leave unobserved (the
/// depth of an object seen from one side) near its category's typical size, and bounds every
/// semi-axis, so no fit degenerates to a disc or a needle. Objects whose projections keep
/// overlapping their boxes poorly are rejected.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/box.hpp"
#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/ellipsoid.hpp"

namespace ellreloc {

/// One view of an object: the keyframe's world->camera pose and the detection box.
struct BoxView {
  Pose pose;
  Box box;
  /// The image border cuts the box (the object may go on past it); unset: judged from the box
  /// (within BoxEllipsoidOptions::border_px of the border). Set for boxes undistorted from a raw
  /// image, whose border is not the pinhole image's.
  std::optional<bool> cut;
};

/// What is known of an object's size before its boxes: its category's typical semi-axes
/// (category_sizes.hpp). Each log semi-axis, sorted, is pulled towards the typical one sorted,
/// with a standard deviation of sigma_log (so the prior never fixes the orientation), and every
/// semi-axis stays within [smallest typical / range_factor, largest typical * range_factor],
/// itself within [min_axis, max_axis].
struct BoxSizePrior {
  Eigen::Vector3d typical_semi_axes = Eigen::Vector3d::Constant(0.15);
  double sigma_log = 1.0;  ///< weak: it decides what the boxes leave open
  double range_factor = 4.0;
  double min_axis = 0.005;  ///< metres
  double max_axis = 5.0;
};

struct BoxEllipsoidOptions {
  size_t min_views = 3;
  /// Below this angle between the rays to the object, triangulation cannot tell its depth: the
  /// size prior then places it where the category's typical size fills the boxes (the fit
  /// weighs what parallax there is against the prior); without the prior, NoBaseline.
  double min_baseline_deg = 5.0;
  /// Boxes within this many pixels of the image border cut the object; they are left out of
  /// the fit while at least min_views other views remain.
  double border_px = 2.0;
  /// Reject when the median IoU of the projected ellipsoid's bounding box with the detection
  /// box stays below this after refinement.
  double min_median_iou = 0.5;
  int max_iterations = 100;
  /// At most this many views enter the fit, evenly spread over the given order (time), which
  /// bounds the cost of a fit for an object seen in thousands of frames.
  size_t max_views = 60;
  /// Scale of the Cauchy loss on each view's residual (the W2 between the box-inscribed
  /// ellipse and the projection, over the box's size): a box that disagrees with the others by
  /// more than about this (a detector's box of a part of the object, of an occluded or a
  /// mis-associated one) weighs less and less, where a convex loss would let it pull the fit.
  double loss_scale = 0.25;
  bool use_size_prior = true;
  /// When set (world coordinates, against gravity), the ellipsoid stands upright: its third
  /// axis is `up` and only its yaw is fitted, as the paper's RGB-D ellipsoids (PCA yaw).
  std::optional<Eigen::Vector3d> up;
};

enum class BoxEllipsoidStatus {
  Ok,
  TooFewViews,   ///< fewer than min_views valid views
  NoBaseline,    ///< the viewing rays are nearly parallel and no size prior places the object
  BehindCamera,  ///< the triangulated centre is behind a camera
  PoorFit,       ///< reprojection IoU below min_median_iou
  InvalidInput,  ///< invalid intrinsics, poses or boxes
};
const char* toString(BoxEllipsoidStatus status);

struct BoxEllipsoidResult {
  BoxEllipsoidStatus status = BoxEllipsoidStatus::InvalidInput;
  Ellipsoid ellipsoid;        ///< meaningful for Ok (and PoorFit: the rejected estimate)
  double median_iou = 0.0;    ///< projected bounding box vs detection box, over the views used
  double baseline_deg = 0.0;  ///< largest angle between two viewing rays
  int views_used = 0;
  bool depth_from_size = false;  ///< triangulation could not tell the depth: the size prior placed it
  std::string reason;            ///< why it failed, in a few words
  bool ok() const { return status == BoxEllipsoidStatus::Ok; }
};

/// Builds an object's ellipsoid from its boxes. Never throws; invalid input gives a status.
BoxEllipsoidResult buildEllipsoidFromBoxes(const Intrinsics& K, const std::vector<BoxView>& views,
                                           const BoxEllipsoidOptions& options = {}, const BoxSizePrior& prior = {});

/// The half-size of a box in the normalised image (the mean of its half-width over fx and
/// half-height over fy): the radius, per unit of depth, of the object it boxes.
inline double boxRadiusPerDepth(const Intrinsics& K, const Box& box) {
  return 0.25 * (box.width() / K.fx + box.height() / K.fy);
}

/// The centre least-squares closest to the rays through the box centres (nullopt when the
/// rays are parallel or the input is invalid). Exposed for the mapper's association.
std::optional<Eigen::Vector3d> triangulateBoxCentres(const Intrinsics& K, const std::vector<BoxView>& views);

/// Where the box of an object not yet fitted may appear from `pose`: its last box moved with
/// the camera and scaled by the change of depth. The object is taken at the point nearest to
/// the rays through its boxes' centres when they span at least `min_baseline_deg` (one box);
/// else on them where its category's typical size fills the boxes, and also up to the prior's
/// `range_factor` times nearer or farther along the last ray, in steps of sqrt(2) (nine boxes
/// for the default 4: a real object is not its category's typical size). Empty when the object
/// would be behind a camera or the input is invalid. For 2D tracking between keyframes far
/// apart (a SLAM system's), where a small object moves further than its size in the image.
std::vector<Box> predictedBoxes(const Intrinsics& K, const std::vector<BoxView>& views, const BoxSizePrior& prior,
                                double min_baseline_deg, const Pose& pose);

}  // namespace ellreloc
