#pragma once
/// \file box_ellipsoid_builder.hpp
/// Monocular object mapping from boxes: an ellipsoid from three or more detection boxes of one
/// object seen from known camera poses (as OA-SLAM and QuadricSLAM users have them). The centre
/// is triangulated from the rays through the box centres, the semi-axes start from the box
/// sizes at that depth, and the 9-DoF ellipsoid (centre, semi-axes, rotation) is refined by
/// minimising the squared Wasserstein distance between each box-inscribed ellipse and the
/// ellipsoid's projection (Ceres). Objects whose projections keep overlapping their boxes
/// poorly are rejected.

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
};

struct BoxEllipsoidOptions {
  size_t min_views = 3;
  /// The rays to the object must span at least this angle, else depth is unobservable.
  double min_baseline_deg = 5.0;
  /// Boxes within this many pixels of the image border cut the object; they are left out of
  /// the fit while at least min_views other views remain.
  double border_px = 2.0;
  /// Reject when the median IoU of the projected ellipsoid's bounding box with the detection
  /// box stays below this after refinement.
  double min_median_iou = 0.5;
  int max_iterations = 100;
};

enum class BoxEllipsoidStatus {
  Ok,
  TooFewViews,   ///< fewer than min_views valid views
  NoBaseline,    ///< the viewing rays are nearly parallel
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
  std::string reason;  ///< why it failed, in a few words
  bool ok() const { return status == BoxEllipsoidStatus::Ok; }
};

/// Builds an object's ellipsoid from its boxes. Never throws; invalid input gives a status.
BoxEllipsoidResult buildEllipsoidFromBoxes(const Intrinsics& K, const std::vector<BoxView>& views,
                                           const BoxEllipsoidOptions& options = {});

/// The centre least-squares closest to the rays through the box centres (nullopt when the
/// rays are parallel or the input is invalid). Exposed for the mapper's association.
std::optional<Eigen::Vector3d> triangulateBoxCentres(const Intrinsics& K, const std::vector<BoxView>& views);

}  // namespace ellreloc
