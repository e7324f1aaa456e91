#pragma once
/// \file writer.hpp
/// Lays a simulated scene out as files in the TUM layout of docs/formats.md, ready for the
/// command line and for benchmarks:
///
///     DIR/camera.yaml                 ORB-SLAM style intrinsics
///     DIR/map_groundtruth.json        the true ellipsoids (inscribed in the objects' cuboids)
///     DIR/map_perturbed.json          the same with a mapper's errors (the noise level's)
///     DIR/mapping/associations.txt    t_rgb rgb/T.png t_depth depth/T.png
///     DIR/mapping/rgb/, depth/        colour-coded renderings, 16-bit depth PNGs (5000 / m)
///     DIR/mapping/trajectory.txt      TUM, camera->world
///     DIR/mapping/detections.json     boxes + instance masks (COCO RLE), with object_id
///     DIR/mapping/ellipse_truth.json  per detection: true projected ellipse and regular verdict (sim/truth.hpp)
///     DIR/query/rgb/                  colour-coded renderings of the query frames
///     DIR/query/detections.json       boxes + masks of the query frames, keypoints matched to the map points
///     DIR/query/ellipse_truth.json    the same truth for the query frames
///     DIR/query/groundtruth.txt       TUM, camera->world

#include <cstdint>
#include <string>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/sim/noise.hpp"
#include "ellreloc/sim/scene.hpp"

namespace ellreloc::sim {

struct SimulationOptions {
  ScenePreset preset = ScenePreset::Office;
  uint64_t seed = 0;
  NoiseLevel noise = NoiseLevel::Realistic;
  int mapping_frames = 60;
  int query_frames = 100;
  Intrinsics camera = Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480);
  bool write_rgb = true;  ///< colour-coded renderings (for people; the library does not need them)
};

struct SimulationSummary {
  std::vector<std::string> files;  ///< every file written, relative to DIR
  int objects = 0;
  int mapping_frames = 0;
  int query_frames = 0;
  int query_detections = 0;
};

/// Simulates and writes a scene into `dir` (created if needed). Same options, same files.
/// Throws ellreloc::Error naming the path when something cannot be written.
SimulationSummary writeSimulation(const std::string& dir, const SimulationOptions& options);

}  // namespace ellreloc::sim
