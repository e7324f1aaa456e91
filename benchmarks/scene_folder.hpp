#pragma once
// A synthetic scene on disk with its ground truth, in either of two layouts:
//   - the independent renderer's (shared/data/independent_synth/*): map.json, map_noisy.json,
//     query.detections.json, query.groundtruth.txt, ellipse_truth.json, mapping.detections.json,
//     mapping.trajectory.txt, mapping.ellipse_truth.json, associations.txt;
//   - `ellreloc simulate`'s (sim/writer.hpp): map_groundtruth.json, map_perturbed.json,
//     query/{detections.json, groundtruth.txt, ellipse_truth.json},
//     mapping/{detections.json, trajectory.txt, ellipse_truth.json, associations.txt}.
// Both have camera.yaml. An ellipse-truth file has the detections format: per detection that
// shows an object, the same bbox, `object_id`, `ellipse` (the true projection) and `regular`.
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/object_map.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "ellreloc/io/trajectory.hpp"

namespace ellreloc::bench {

struct SceneFolder {
  std::string name;  ///< the folder's base name
  Intrinsics K;
  ObjectMap exact_map, perturbed_map;
  std::vector<DetectionFrame> query, query_truth, mapping, mapping_truth;
  std::vector<io::StampedPose> query_poses, mapping_poses;
  std::map<std::string, std::string> depth_of_rgb;  ///< mapping frame file_name -> depth PNG path
};

inline SceneFolder loadSceneFolder(const std::string& dir) {
  namespace fs = std::filesystem;
  const bool independent = fs::exists(dir + "/query.detections.json");
  if (!independent && !fs::exists(dir + "/query/detections.json"))
    throw Error(dir + ": not a scene folder (neither query.detections.json nor query/detections.json)");
  auto path = [&](const char* independent_name, const char* simulate_name) {
    return dir + "/" + (independent ? independent_name : simulate_name);
  };
  SceneFolder s;
  s.name = fs::path(dir).lexically_normal().filename().string();
  if (s.name.empty()) s.name = fs::path(dir).lexically_normal().parent_path().filename().string();
  s.K = io::readCamera(dir + "/camera.yaml");
  s.exact_map = io::readMap(path("map.json", "map_groundtruth.json"));
  s.perturbed_map = io::readMap(path("map_noisy.json", "map_perturbed.json"));
  s.query = io::readDetections(path("query.detections.json", "query/detections.json"));
  s.query_truth = io::readDetections(path("ellipse_truth.json", "query/ellipse_truth.json"));
  s.query_poses = io::readTumTrajectory(path("query.groundtruth.txt", "query/groundtruth.txt"));
  s.mapping = io::readDetections(path("mapping.detections.json", "mapping/detections.json"));
  s.mapping_truth = io::readDetections(path("mapping.ellipse_truth.json", "mapping/ellipse_truth.json"));
  s.mapping_poses = io::readTumTrajectory(path("mapping.trajectory.txt", "mapping/trajectory.txt"));
  for (const io::Association& a : io::readAssociations(path("associations.txt", "mapping/associations.txt")))
    for (const DetectionFrame& f : s.mapping)
      if (fs::path(a.rgb_path).filename() == fs::path(f.file_name).filename())
        s.depth_of_rgb[f.file_name] = a.depth_path;
  return s;
}

/// The truth of frame `f`'s detection `d` (the truth entry with the same box), or nullptr.
inline const Detection* truthOf(const std::vector<DetectionFrame>& truth, const DetectionFrame& f, const Detection& d) {
  for (const DetectionFrame& t : truth) {
    if (t.file_name != f.file_name) continue;
    for (const Detection& td : t.detections)
      if (std::abs(td.bbox.x1 - d.bbox.x1) < 1e-6 && std::abs(td.bbox.y1 - d.bbox.y1) < 1e-6 &&
          std::abs(td.bbox.x2 - d.bbox.x2) < 1e-6 && std::abs(td.bbox.y2 - d.bbox.y2) < 1e-6)
        return &td;
  }
  return nullptr;
}

}  // namespace ellreloc::bench
