#pragma once
/// \file map_observations.hpp
/// The observations a camera at a known pose would make of a map's ellipsoids: each projected
/// ellipse, optionally with noise, as an Observation. The quick way to make relocalization
/// problems with known answers (tests, benchmarks, notebooks); render.hpp makes full images.

#include <random>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/object_map.hpp"
#include "ellreloc/core/observation.hpp"
#include "ellreloc/core/projection.hpp"

namespace ellreloc::sim {

struct MapObservationOptions {
  bool inside_image_only = true;  ///< drop objects whose projected ellipse's box leaves the image
  double centre_sigma_px = 0.0;   ///< Gaussian noise on the ellipse centre, pixels
  double axis_sigma = 0.0;        ///< relative Gaussian noise on both semi-axes (one draw per object)
  int max_observations = 0;       ///< stop after this many; 0: every visible object
};

/// Observations of every object of `map` that projects at `pose` (source Given: the ellipse is
/// the projection, its box the ellipse's bounding box, the category the object's). `objects`
/// receives each observation's object index. Noise needs `rng`: per object the centre's x and
/// y are drawn, then the axis scale when axis_sigma > 0.
template <typename Rng = std::mt19937>
std::vector<Observation> observeMap(const ObjectMap& map, const Intrinsics& K, const Pose& pose,
                                    const MapObservationOptions& options = {}, Rng* rng = nullptr,
                                    std::vector<int>* objects = nullptr) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Observation> out;
  if (objects) objects->clear();
  for (size_t j = 0; j < map.objects.size(); ++j) {
    const Projection p = project(map.objects[j].ellipsoid, K, pose);
    if (!p) continue;
    const Box b = p.ellipse.boundingBox();
    if (options.inside_image_only && (b.x1 < 0 || b.y1 < 0 || b.x2 > K.width || b.y2 > K.height)) continue;
    Eigen::Vector2d centre = p.ellipse.center();
    Eigen::Vector2d axes = p.ellipse.axes();
    if (rng) {
      const double dx = normal(*rng);
      const double dy = normal(*rng);
      centre += options.centre_sigma_px * Eigen::Vector2d(dx, dy);
      if (options.axis_sigma > 0.0) axes *= 1.0 + options.axis_sigma * normal(*rng);
    }
    Observation o;
    o.category = map.objects[j].category;
    o.ellipse = Ellipse(centre, axes, p.ellipse.angle());
    o.box = o.ellipse.boundingBox();
    o.source = EllipseSource::Given;
    out.push_back(o);
    if (objects) objects->push_back(static_cast<int>(j));
    if (options.max_observations > 0 && static_cast<int>(out.size()) == options.max_observations) break;
  }
  return out;
}

}  // namespace ellreloc::sim
