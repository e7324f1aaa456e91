#pragma once
// Loads the fr2_desk keyframe benchmark: map, camera, and per keyframe its box observations
// and pose (the keyframe poses of the SLAM run that built the map).

#include <string>
#include <vector>

#include "ellreloc/core/observation.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/trajectory.hpp"

namespace ellreloc::bench {

struct Query {
  std::string timestamp;
  std::vector<Observation> observations;
  Pose truth;
};

struct RelocalizationDataset {
  std::string name;
  ObjectMap map;
  Intrinsics K;
  std::vector<Query> queries;
  Eigen::Vector3d up_in_map = Eigen::Vector3d::UnitZ();  ///< for the simulated IMU of the gravity rows
};

inline RelocalizationDataset loadFr2Desk(const std::string& data_dir) {
  RelocalizationDataset d;
  d.name = "fr2_desk keyframes";
  const std::string dir = data_dir + "/tum_fr2_desk/";
  d.map = io::readMap(dir + "map.json");
  d.K = io::readCamera(dir + "camera.yaml");
  const auto poses = io::readTumTrajectory(dir + "keyframes.groundtruth.txt");
  for (const DetectionFrame& f : io::readDetections(dir + "keyframes.detections.json")) {
    const Pose* pose = io::framePose(poses, f);
    if (!pose) continue;
    Query q{f.timestampText(), {}, *pose};
    for (const Detection& det : f.detections) {
      if (auto o = observationFromBox(det.category_id, det.score, det.bbox, d.K.width, d.K.height))
        q.observations.push_back(*o);
    }
    d.queries.push_back(std::move(q));
  }
  // The map is in the first camera's frame: take the mean of the keyframes' image "up" (-y)
  // as gravity, which a hand-held camera keeps near upright.
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const Query& q : d.queries) up -= q.truth.rotation().row(1).transpose();
  d.up_in_map = up.normalized();
  return d;
}

}  // namespace ellreloc::bench
