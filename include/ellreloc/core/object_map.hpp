#pragma once
/// \file object_map.hpp
/// A map of objects (ellipsoids with categories) and, optionally, 3D feature points.

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "ellreloc/core/ellipsoid.hpp"

namespace ellreloc {

struct MapObject {
  int id = 0;
  int category = 0;   ///< 0-based COCO-80 id in the shipped data; the most frequent label
  std::string label;  ///< optional human-readable name
  Ellipsoid ellipsoid;
  /// Optional label histogram from mapping (how often the detector gave each category to
  /// this object; GOReloc maps and the voxel mapper keep one). Empty: `category` only.
  std::map<int, double> category_counts = {};

  /// Share of the detections of this object that carried category c: from the histogram
  /// when there is one, else 1 for `category` and 0 otherwise.
  double categoryShare(int c) const {
    if (category_counts.empty()) return c == category ? 1.0 : 0.0;
    double total = 0.0, mine = 0.0;
    for (const auto& [k, n] : category_counts) {
      total += n;
      if (k == c) mine = n;
    }
    return total > 0.0 ? mine / total : (c == category ? 1.0 : 0.0);
  }
};

struct ObjectMap {
  std::vector<MapObject> objects;
  std::vector<Eigen::Vector3d> points;  ///< optional map points, indexed by keypoint matches
};

}  // namespace ellreloc
