#pragma once
/// \file floor.hpp
/// The up direction (against gravity) from a depth image: the dominant plane whose normal is
/// within a few degrees of a prior (the floor, or table tops parallel to it), found by a seeded
/// RANSAC over back-projected depth pixels and refined by least squares on its inliers. Used by
/// the mapper when the world frame's z axis is not known to be vertical.

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/depth_image.hpp"

namespace ellreloc {

struct FloorOptions {
  Eigen::Vector3d prior_up = Eigen::Vector3d::UnitZ();  ///< world frame
  double max_tilt_deg = 25.0;                           ///< planes tilted more from the prior are walls, not floors
  double inlier_distance = 0.02;                        ///< metres
  double min_inlier_share = 0.10;                       ///< of the sampled pixels
  int pixel_stride = 4;                                 ///< sample every n-th pixel in x and y
  int iterations = 200;
  uint64_t seed = 0;
};

struct FloorPlane {
  Eigen::Vector3d up;   ///< unit normal, oriented like the prior, world frame
  double offset = 0.0;  ///< plane: up . x = offset
  double inlier_share = 0.0;
};

/// The floor (or a plane parallel to it) seen by a keyframe with world->camera `pose`;
/// nullopt when no plane within max_tilt_deg of the prior holds min_inlier_share of the pixels.
std::optional<FloorPlane> estimateFloor(const Intrinsics& K, const Pose& pose, const DepthImage& depth,
                                        const FloorOptions& options = {});

}  // namespace ellreloc
