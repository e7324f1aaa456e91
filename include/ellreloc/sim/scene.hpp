#pragma once
/// \file scene.hpp
/// Seeded synthetic indoor scenes with ground truth: objects built from boxes and cylinders
/// resting on the floor or on tables, yaw-rotated only (world z up, floor at z = 0), each with
/// a COCO-80 category and a plausible size; the ground-truth ellipsoid of an object is the one
/// inscribed in its oriented bounding cuboid. Plus camera trajectories and map points.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/object_map.hpp"

namespace ellreloc::sim {

enum class PrimitiveShape { Box, Cylinder, Ellipsoid };

/// A convex solid: a box with half-extents `half`, a cylinder of radius half(0) and
/// half-height half(2) along its local z, or an ellipsoid of semi-axes `half`; placed by
/// `center` and `rotation` (local -> world).
struct Primitive {
  PrimitiveShape shape = PrimitiveShape::Box;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d half = Eigen::Vector3d::Ones();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
};

struct SimObject {
  int id = 0;
  int category = 0;
  std::string label;
  std::vector<Primitive> parts;
  /// Oriented bounding cuboid (yaw only): centre, half-extents, rotation.
  Eigen::Vector3d box_center = Eigen::Vector3d::Zero();
  Eigen::Vector3d box_half = Eigen::Vector3d::Ones();
  Eigen::Matrix3d box_rotation = Eigen::Matrix3d::Identity();
  /// The ellipsoid inscribed in the bounding cuboid.
  Ellipsoid ellipsoid() const { return Ellipsoid(box_center, box_half, box_rotation); }
};

enum class ScenePreset {
  Office,     ///< ~20 objects of varied categories on two desks, a shelf and the floor
  Cluttered,  ///< ~40 objects, many of the same category (cups, books, bottles)
  Sparse,     ///< ~6 objects
};

struct Scene {
  std::vector<SimObject> objects;
  std::vector<Primitive> furniture;     ///< tables and shelves: they occlude, but are not objects
  std::vector<Eigen::Vector3d> points;  ///< 3D feature points on object and furniture surfaces
  double room_half_size = 2.5;          ///< the room spans [-s, s]^2 on the floor

  /// The ground-truth object map (ellipsoids, categories, labels, points).
  ObjectMap groundTruthMap() const;
};

/// A scene for a preset; same preset and seed, same scene.
Scene makeScene(ScenePreset preset, uint64_t seed);

/// The mapping trajectory: a loop around the room's centre at eye height (1.4 m), looking in.
std::vector<Pose> mappingTrajectory(const Scene& scene, int frames);

/// The query trajectory with a strong change of viewpoint: other heights (0.8-2.0 m), radii
/// and headings than the mapping loop, seeded.
std::vector<Pose> queryTrajectory(const Scene& scene, int frames, uint64_t seed);

/// Name <-> preset ("office", "cluttered", "sparse").
const char* toString(ScenePreset preset);
bool parsePreset(const std::string& name, ScenePreset* preset);

}  // namespace ellreloc::sim
