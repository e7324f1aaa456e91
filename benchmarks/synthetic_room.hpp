#pragma once
// A synthetic room shared by the pose benchmarks: n ellipsoids on a 3 x 3 m floor plan at
// table heights, cameras on a circle around it looking in, and noisy observations.

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "ellreloc/core/object_map.hpp"
#include "ellreloc/core/observation.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/sim/map_observations.hpp"

namespace ellreloc::bench {

inline const Intrinsics kK(525.0, 525.0, 319.5, 239.5, 640, 480);

/// A room of n objects (categories 0..categories-1) on a 4 x 4 m floor plan, and camera poses
/// at 1.2-1.6 m height looking at the middle of the room.
struct Room {
  ObjectMap map;
  std::vector<Pose> cameras;
};

inline Room makeRoom(int n, int categories, int cameras, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Room room;
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(6.28 * u(rng), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d axes(0.05 + 0.25 * u(rng), 0.05 + 0.25 * u(rng), 0.05 + 0.2 * u(rng));
    room.map.objects.push_back(
        {i, i % categories, "", Ellipsoid({-1.5 + 3 * u(rng), -1.5 + 3 * u(rng), axes(2) + 0.75 * u(rng)}, axes, R)});
  }
  while (static_cast<int>(room.cameras.size()) < cameras) {
    const double a = 6.28 * u(rng);
    const Eigen::Vector3d c(2.8 * std::cos(a), 2.8 * std::sin(a), 1.2 + 0.4 * u(rng));
    const Eigen::Vector3d target(0.3 * u(rng), 0.3 * u(rng), 0.4);
    room.cameras.push_back(Pose::lookAt(c, target));
  }
  return room;
}

/// Observations of up to `max_obs` visible objects with 1 px of centre noise and 3% axis noise.
inline std::vector<Observation> observe(const Room& room, const Pose& pose, int max_obs, std::mt19937& rng) {
  sim::MapObservationOptions noise;
  noise.centre_sigma_px = 1.0;
  noise.axis_sigma = 0.03;
  noise.max_observations = max_obs;
  return sim::observeMap(room.map, kK, pose, noise, &rng);
}

}  // namespace ellreloc::bench
