#pragma once
/// \file object_map.hpp
/// A map of objects (ellipsoids with categories) and, optionally, 3D feature points.

#include <Eigen/Core>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/camera_envelope.hpp"
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
  /// Optional: the heights and tilts the map's keyframes were taken at (widened); the
  /// relocalizer keeps the camera within them (RelocalizerOptions::map_envelope).
  std::optional<CameraEnvelope> camera_envelope;
  /// Metres per unit of the map's coordinates: 1 for a metric map. A monocular SLAM system's
  /// map is in a unit of its own (MapperOptions::unit_metres); the bounds on semi-axes and the
  /// relocalizer's distances, which are in metres, are converted with it.
  double unit_metres = 1.0;
};

/// The lengths a unit of a map's (or a trajectory's) coordinates may have, in metres.
constexpr double kMinUnitMetres = 1e-6;
constexpr double kMaxUnitMetres = 1e6;

/// The map's unit is a length (finite, positive; kMinUnitMetres to kMaxUnitMetres).
inline bool validUnitMetres(double unit_metres) {
  return unit_metres >= kMinUnitMetres && unit_metres <= kMaxUnitMetres;
}

/// Semi-axes outside [kMinSemiAxis, kMaxSemiAxis] metres make an object unusable: a
/// sub-millimetre axis is a degenerate fit (a disc or a needle), above 10 m no indoor object.
constexpr double kMinSemiAxis = 1e-3;
constexpr double kMaxSemiAxis = 10.0;

/// Why `object` cannot be used for relocalization, in a few words, or "" when it can: a
/// non-finite centre or rotation, a semi-axis non-finite or outside [kMinSemiAxis,
/// kMaxSemiAxis] metres (`unit_metres`: metres per unit of the map), or a rotation that is
/// not one.
inline std::string mapObjectProblem(const MapObject& object, double unit_metres = 1.0) {
  const Ellipsoid& e = object.ellipsoid;
  if (!e.center().allFinite()) return "centre is not finite";
  if (!e.axes().allFinite()) return "a semi-axis is not finite";
  char text[96];
  const auto outside = [&](double axis, const char* bound) {
    if (unit_metres == 1.0)
      std::snprintf(text, sizeof text, "semi-axis %.3g m is %s", axis, bound);
    else
      std::snprintf(text, sizeof text, "semi-axis %.3g (%.3g m) is %s", axis, axis * unit_metres, bound);
    return std::string(text);
  };
  if (!(e.axes().minCoeff() * unit_metres >= kMinSemiAxis)) return outside(e.axes().minCoeff(), "below 1 mm");
  if (!(e.axes().maxCoeff() * unit_metres <= kMaxSemiAxis)) return outside(e.axes().maxCoeff(), "above 10 m");
  if (!isRotation(e.rotation())) return "rotation is not a rotation matrix";
  return "";
}

/// The object can be used for relocalization (mapObjectProblem finds nothing; the text is
/// only built for an unusable object).
inline bool mapObjectUsable(const MapObject& object, double unit_metres = 1.0) {
  return mapObjectProblem(object, unit_metres).empty();
}

}  // namespace ellreloc
