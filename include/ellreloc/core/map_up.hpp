#pragma once
/// \file map_up.hpp
/// Which way is up in a map that carries neither mapping poses nor a known vertical (a map from
/// another SLAM system), from its objects alone. Indoor objects spread over floors and desk tops
/// far more than up the walls, so the direction in which their centres spread least lies close to
/// the vertical; its sign follows from what the objects are: a monitor stands higher than a
/// keyboard, a keyboard higher than the centre of a chair. With it the relocalizer keeps the
/// camera from turning upside down (CameraEnvelope::upright), which rules out look-alike poses
/// from under a desk or rolled over that explain a few boxes as well as the true one.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "ellreloc/core/object_map.hpp"

namespace ellreloc {

/// The usual height above the floor of the centre of an indoor object of COCO-80 category
/// `coco_id` (0-based), in metres: on the floor (a chair's seat, a bed), on a desk or table (a
/// keyboard, a cup), above it (a monitor), on a wall (a clock). NaN for categories with no usual
/// place indoors (vehicles, animals, sports gear) or an id outside COCO-80.
inline double typicalCentreHeight(int coco_id) {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  // clang-format off
  static constexpr std::array<double, 80> kHeights = {{
      0.90, kNone, kNone, kNone, kNone, kNone, kNone, kNone,  // person bicycle car motorcycle airplane bus train truck
      kNone, kNone, kNone, kNone, kNone, 0.40, kNone, kNone,  // boat traffic-light hydrant stop-sign meter bench bird cat
      kNone, kNone, kNone, kNone, kNone, kNone, kNone, kNone,  // dog horse sheep cow elephant bear zebra giraffe
      0.30, kNone, 0.40, kNone, 0.35, kNone, kNone, kNone,     // backpack umbrella handbag tie suitcase frisbee skis snowboard
      kNone, kNone, kNone, kNone, kNone, kNone, kNone, 0.85,   // ball kite bat glove skateboard surfboard racket bottle
      0.80, 0.80, 0.75, 0.75, 0.75, 0.80, 0.80, 0.80,          // wine-glass cup fork knife spoon bowl banana apple
      0.80, 0.80, 0.80, 0.80, 0.80, 0.80, 0.80, 0.80,          // sandwich orange broccoli carrot hot-dog pizza donut cake
      0.50, 0.45, 0.55, 0.45, 0.40, 0.40, 1.00, 0.85,          // chair couch potted-plant bed table toilet tv laptop
      0.75, 0.65, 0.75, 0.75, 1.05, 0.45, 1.00, 0.85,          // mouse remote keyboard phone microwave oven toaster sink
      0.90, 0.85, 1.60, 0.85, 0.75, 0.60, 1.00, 1.00,          // refrigerator book clock vase scissors teddy-bear drier toothbrush
  }};
  // clang-format on
  return coco_id >= 0 && coco_id < static_cast<int>(kHeights.size()) ? kHeights[static_cast<size_t>(coco_id)] : kNone;
}

struct MapUp {
  Eigen::Vector3d up;  ///< unit, map frame
  /// t statistic of the correlation between the objects' usual heights and their positions
  /// along `up`: how surely the sign (and the axis) is right.
  double t = 0.0;
  int objects = 0;  ///< objects of a category with a usual height
};

/// The up direction of `map` from its objects: the direction of least spread of the usable
/// objects' centres, signed so that the usual heights of their categories rise along it. Given
/// only when the evidence is clear: at least 8 objects of categories with a usual height, the
/// least spread at most 0.75 of the next (the direction is defined), and the heights correlated
/// with the positions along it with a t statistic of at least `min_t` (2.5: about one chance in
/// sixty that unrelated heights give as much) and more than along either other principal
/// direction (which a horizontal direction of least spread, objects along one wall, would fail).
/// nullopt otherwise.
inline std::optional<MapUp> estimateMapUp(const ObjectMap& map, double min_t = 2.5) {
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> heights;
  std::vector<size_t> known;  // the centres of a category with a usual height
  for (const MapObject& o : map.objects) {
    if (!mapObjectUsable(o, map.unit_metres)) continue;
    const double height = typicalCentreHeight(o.category);
    if (std::isfinite(height)) known.push_back(centres.size());
    centres.push_back(o.ellipsoid.center());
    heights.push_back(height);
  }
  const int n = static_cast<int>(known.size());
  if (n < 8) return std::nullopt;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& c : centres) mean += c;
  mean /= static_cast<double>(centres.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& c : centres) scatter += (c - mean) * (c - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> spread(scatter);
  const Eigen::Vector3d variances = spread.eigenvalues();  // ascending
  if (spread.info() != Eigen::Success || !(variances(0) <= 0.75 * 0.75 * variances(1))) return std::nullopt;

  // Pearson correlation of the usual heights with the positions along each principal direction.
  double mean_h = 0.0;
  for (size_t i : known) mean_h += heights[i];
  mean_h /= n;
  std::array<double, 3> t{};
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d d = spread.eigenvectors().col(axis);
    double mean_s = 0.0;
    for (size_t i : known) mean_s += d.dot(centres[i]);
    mean_s /= n;
    double shh = 0.0, sss = 0.0, shs = 0.0;
    for (size_t i : known) {
      const double dh = heights[i] - mean_h, ds = d.dot(centres[i]) - mean_s;
      shh += dh * dh, sss += ds * ds, shs += dh * ds;
    }
    if (!(shh > 0.0 && sss > 0.0)) return std::nullopt;
    const double r = std::clamp(shs / std::sqrt(shh * sss), -1.0 + 1e-12, 1.0 - 1e-12);
    t[static_cast<size_t>(axis)] = r * std::sqrt((n - 2) / (1.0 - r * r));
  }
  const double t_up = std::abs(t[0]);
  if (!(t_up >= min_t && t_up > std::abs(t[1]) && t_up > std::abs(t[2]))) return std::nullopt;
  MapUp result;
  result.up = spread.eigenvectors().col(0).normalized() * (t[0] > 0.0 ? 1.0 : -1.0);
  result.t = t_up;
  result.objects = n;
  return result;
}

}  // namespace ellreloc
