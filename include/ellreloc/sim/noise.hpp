#pragma once
/// \file noise.hpp
/// Seeded noise models that turn rendered ground truth into what a detector, a depth sensor
/// and a mapper would give: mask boundary noise (random erosion or dilation), box jitter,
/// missed detections, false positives, label confusion, depth noise growing with distance, and
/// a perturbed map (centre, axis and yaw errors).

#include <random>
#include <string>
#include <vector>

#include "ellreloc/core/object_map.hpp"
#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/depth_image.hpp"
#include "ellreloc/sim/render.hpp"
#include "ellreloc/sim/scene.hpp"

namespace ellreloc::sim {

enum class NoiseLevel { None, Realistic, Hard };

struct NoiseModel {
  int mask_boundary_px = 0;         ///< masks eroded or dilated by up to this many pixels
  double mask_flip_rate = 0.0;      ///< pixels toggled around each mask, as a share of its area
  double box_jitter_px = 0.0;       ///< standard deviation of each box edge
  double miss_rate = 0.0;           ///< share of visible objects not detected
  double false_positives = 0.0;     ///< expected false detections per frame
  double label_confusion = 0.0;     ///< share of detections given a wrong category
  double depth_sigma_at_2m = 0.0;   ///< depth noise (m) at 2 m, growing with the square of depth
  double min_visible_pixels = 150;  ///< smaller visible parts are not detected
  double keypoint_sigma_px = 0.0;   ///< pixel noise of keypoints matched to map points
  double keypoint_outliers = 0.0;   ///< share of keypoint matches that are wrong
  // A realistic mapper's errors, for the perturbed map:
  double map_centre_sigma = 0.0;  ///< metres, per axis
  double map_axis_sigma = 0.0;    ///< relative
  double map_yaw_sigma_deg = 0.0;

  static NoiseModel preset(NoiseLevel level);
};

const char* toString(NoiseLevel level);
bool parseNoiseLevel(const std::string& name, NoiseLevel* level);

/// Detections of one rendered frame: a box and an instance mask per visible object, with noise.
/// `object_id` carries the ground-truth object index (kept by the writer for evaluation).
std::vector<Detection> detect(const Scene& scene, const RenderedFrame& frame, const NoiseModel& noise,
                              std::mt19937_64& rng);

/// Keypoints of a frame: the map points visible from the pose (in front, inside the image, not
/// hidden: within 3 cm of the rendered depth), with pixel noise, a share of them matched to a
/// wrong map point (as a feature matcher's outliers).
std::vector<Keypoint> keypoints(const Scene& scene, const RenderedFrame& frame, const Intrinsics& K, const Pose& pose,
                                const NoiseModel& noise, std::mt19937_64& rng);

/// The frame's depth in metres with noise (sigma growing with depth^2); 0 stays 0.
DepthImage noisyDepth(const RenderedFrame& frame, const NoiseModel& noise, std::mt19937_64& rng);

/// The ground-truth map with a mapper's errors (centre, axes, yaw; rotations stay yaw-only).
ObjectMap perturbMap(const ObjectMap& map, const NoiseModel& noise, uint64_t seed);

}  // namespace ellreloc::sim
