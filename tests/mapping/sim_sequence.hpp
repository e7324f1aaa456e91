#pragma once
// Rendered RGB-D mapping sequences with known objects, shared by the mapping tests and
// benchmarks: the simulator's mapping loop with noisy depth and noisy instance masks.

#include <random>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "ellreloc/sim/noise.hpp"
#include "ellreloc/sim/render.hpp"
#include "ellreloc/sim/scene.hpp"

namespace ellreloc::test {

struct SimKeyframe {
  Pose pose;
  DepthImage depth;
  std::vector<Detection> detections;  // object_id = index into scene.objects
};

struct SimSequence {
  sim::Scene scene;
  Intrinsics K = Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480);
  std::vector<SimKeyframe> keyframes;
};

/// The mapping noise of the benchmarks: depth sigma 1 cm at 2 m, mask boundaries moved by up
/// to 2 px, 5% of the mask's pixels flipped; no misses, false positives or label confusion
/// unless asked for.
inline sim::NoiseModel mappingNoise() {
  sim::NoiseModel n;
  n.depth_sigma_at_2m = 0.01;
  n.mask_boundary_px = 2;
  n.mask_flip_rate = 0.05;
  n.box_jitter_px = 0.0;
  return n;
}

inline SimSequence makeSimSequence(sim::ScenePreset preset, uint64_t seed, int frames, const sim::NoiseModel& noise) {
  SimSequence s;
  s.scene = sim::makeScene(preset, seed);
  std::mt19937_64 rng(seed * 7919 + 17);
  for (const Pose& pose : sim::mappingTrajectory(s.scene, frames)) {
    const sim::RenderedFrame frame = sim::render(s.scene, s.K, pose);
    SimKeyframe kf;
    kf.pose = pose;
    kf.detections = sim::detect(s.scene, frame, noise, rng);
    kf.depth = sim::noisyDepth(frame, noise, rng);
    s.keyframes.push_back(std::move(kf));
  }
  return s;
}

}  // namespace ellreloc::test
