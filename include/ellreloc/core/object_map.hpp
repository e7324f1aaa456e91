#pragma once
/// \file object_map.hpp
/// A map of objects (ellipsoids with categories) and, optionally, 3D feature points.

#include "ellreloc/core/ellipsoid.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace ellreloc {

struct MapObject {
  int id = 0;
  int category = 0;   ///< 0-based COCO-80 id in the shipped data
  std::string label;  ///< optional human-readable name
  Ellipsoid ellipsoid;
};

struct ObjectMap {
  std::vector<MapObject> objects;
  std::vector<Eigen::Vector3d> points;  ///< optional map points, indexed by keypoint matches
};

}  // namespace ellreloc
