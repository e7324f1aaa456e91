#pragma once
/// \file voxel_object.hpp
/// One object of the voxel map (Zhu et al., "Object-level Voxel Modelling"): a sparse hashed
/// set of voxels, each with the probability that it belongs to the object, updated keyframe by
/// keyframe with the binary Bayes filter of the paper's eq. 1 (prior 0.5). As in OctoMap, the
/// filter runs in log-odds with clamping, so an update is one addition:
///     L(n | z_1:T) = clamp(L(n | z_1:T-1) + logit P(n | z_T)),  logit p = log(p / (1 - p)).
/// A depth pixel inside the object's mask is a hit for the voxel it falls in; a voxel that
/// projects into the frame outside the mask (and is not hidden), or in front of the measured
/// depth inside the mask, is a miss.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "ellreloc/core/box.hpp"
#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/depth_image.hpp"
#include "ellreloc/core/ellipsoid.hpp"
#include "ellreloc/core/mask.hpp"

namespace ellreloc {

struct VoxelOptions {
  /// Metres. 1 cm resolves the thin sides of books, keyboards and monitors (2-4 cm), which a
  /// 2 cm voxel measures to a voxel (axis errors 15-23% instead of 9-10%), at 4-5x the memory.
  double voxel_size = 0.01;
  double hit_probability = 0.7;   ///< P(n | z) of a depth pixel inside the mask (OctoMap's default)
  double miss_probability = 0.3;  ///< P(n | z) of a voxel seen outside the mask or in free space
  double clamp_min = 0.12;        ///< probabilities are clamped to [clamp_min, clamp_max]
  double clamp_max = 0.97;        ///< so that a voxel can change its mind
  /// Voxels at or above this probability make up the object (boxes, ellipsoids, 3D matching).
  double occupied_probability = 0.5;
  /// A voxel this far (metres) in front of the measured depth lies in free space; one this
  /// far behind it is hidden and gets no evidence.
  double depth_tolerance = 0.04;
  double min_depth = 0.1;  ///< depth readings outside [min_depth, max_depth] are ignored
  double max_depth = 8.0;
  /// Masks bleed onto what lies behind or in front of the object: a mask pixel whose depth is
  /// further than max(depth_gate_min, depth_gate_sigmas x sigma) from the median depth of the
  /// mask (sigma from the median absolute deviation) is not a hit. 0 sigmas: no gate.
  double depth_gate_sigmas = 3.0;
  double depth_gate_min = 0.1;
  /// A 3x3 majority vote cleans the mask first: isolated pixels a segmentation network got
  /// wrong (specks around the object, pinholes inside) would otherwise hit the background
  /// voxels next to the object again and again.
  bool mask_majority_filter = true;
  int pixel_stride = 1;  ///< use every n-th mask pixel in x and y (speed vs density)
  /// Memory bound: past this many voxels the least probable ones are dropped (about 40 bytes
  /// per voxel with its key and index, so 200,000 voxels is about 8 MB per object).
  size_t max_voxels = 200000;
};

/// What one keyframe did to an object.
struct VoxelUpdate {
  long hits = 0;    ///< voxels given a hit (each at most once per keyframe)
  long misses = 0;  ///< voxels given a miss
  long added = 0;   ///< voxels created
};

class VoxelObject {
 public:
  explicit VoxelObject(const VoxelOptions& options = {});

  /// Integrates one keyframe: world->camera `pose`, its depth image, and the object's mask in
  /// that image (a full-image mask or a crop). Throws ellreloc::Error when the intrinsics,
  /// pose, depth or mask are invalid or their sizes differ.
  VoxelUpdate integrate(const Intrinsics& K, const Pose& pose, const DepthImage& depth, const BinaryMask& mask);

  /// Removes voxels whose probability is below `probability` (the paper's stage-by-stage filter).
  size_t prune(double probability);

  /// Fuses another model of the same object (same options) into this one: the evidence each
  /// model holds for a voxel adds up (log-odds sum of eq. 1, clamped as in integrate()). Misses
  /// the other model's keyframes would have given this model's own voxels are not known, so
  /// they are not counted. The other model's integrate() calls count after this one's (its k-th
  /// becomes this one's n + k-th, n this model's count before): a voxel both hold counts as last
  /// hit by the other's.
  void absorb(const VoxelObject& other);

  /// Moves the object rigidly, x -> R x + t (a host's correction of the keyframes that saw it):
  /// each voxel's mean depth point is moved and falls into the voxel of the grid that holds it
  /// now; where two land in one voxel, it keeps the stronger evidence and their points' mean.
  /// Voxels moved beyond the grid's range (about 10 km from the origin at 1 cm) are dropped.
  void moveRigidly(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

  /// Moves each voxel with the keyframe that last hit it, as moveRigidly moves them all:
  /// `motions[k - 1]` (x -> R x + t, a Pose's transform) for the voxels whose last hit came
  /// from the k-th integrate() (an absorbed model's numbered as absorb() says; past the end of
  /// `motions`, its last). A host that corrects its keyframes by different amounts moves what
  /// each keyframe placed with that keyframe. No motions: nothing moves.
  void moveWithKeyframes(const std::vector<Pose>& motions);

  /// Number of voxels held (any probability).
  size_t size() const { return voxels_.size(); }
  /// Number of voxels at or above options().occupied_probability.
  size_t occupiedCount() const;
  /// Centres of the voxels at or above `min_probability` (default: the occupied ones), in
  /// world coordinates.
  std::vector<Eigen::Vector3d> occupiedCentres(std::optional<double> min_probability = std::nullopt) const;
  /// For each voxel at or above `min_probability` (default: the occupied ones), the mean of the
  /// depth points that fell in it, in world coordinates: the measured surface to a fraction of
  /// a voxel, where a voxel's centre is up to half a voxel off it (what the ellipsoid builder
  /// reads: extents and yaw free of the grid's steps).
  std::vector<Eigen::Vector3d> occupiedPointMeans(std::optional<double> min_probability = std::nullopt) const;
  /// The box of the occupied voxels projected into a camera (clipped to the image), or nullopt
  /// when fewer than `min_voxels` of them land in front of the camera inside the image. With
  /// `within`, only the voxels inside that ellipsoid grown `within_scale` times count (2: the
  /// corners of the cuboid an ellipsoid is inscribed in lie at sqrt(3)), so that stray voxels
  /// far from the object's ellipsoid do not stretch its box.
  std::optional<Box> projectedBox(const Intrinsics& K, const Pose& pose, int min_voxels = 10,
                                  const Ellipsoid* within = nullptr, double within_scale = 2.0) const;
  /// Number of this object's occupied voxels that have an occupied voxel of `other` within
  /// `radius` metres (centre to centre): n(this, other) of the paper's eq. 4. Both objects
  /// must use the same voxel size.
  long countNear(const VoxelObject& other, double radius) const;

  /// The probability of the voxel containing a world point (0.5 when unknown).
  double probabilityAt(const Eigen::Vector3d& x_w) const;
  /// Heap memory in bytes (voxels, keys and index, as allocated).
  size_t memoryBytes() const;

  const VoxelOptions& options() const { return options_; }
  /// The world box of the occupied voxels (empty when there are none).
  Eigen::AlignedBox3d bounds() const;

 private:
  struct Voxel {
    float log_odds = 0.0f;
    uint32_t stamp = 0;  ///< the integrate() that last hit it, counted from 1 (one hit per keyframe)
    /// The mean of the depth points that fell in it, from its centre, in 1/65536 of a voxel
    /// (a voxel spans [-32768, 32768)); `points` of them, counted up to 65535 (later points
    /// then move the mean by 1/65535 of their offset each).
    int16_t mean[3] = {0, 0, 0};
    uint16_t points = 0;
  };
  static constexpr double kMeanUnits = 65536.0;  ///< Voxel::mean units per voxel
  /// Adds points (`count` of them, with mean offset `offset` in voxel units) to a voxel's mean.
  static void addToMean(Voxel& v, const Eigen::Vector3d& offset, long count);
  /// The log-odds at or above which a voxel counts, for `min_probability` (default: occupied).
  float logOddsCut(std::optional<double> min_probability) const;
  Eigen::Vector3d pointMeanOf(uint64_t key, const Voxel& v) const;
  /// point_of(key, voxel) for each voxel at or above `min_probability` (default: occupied).
  template <class PointOf>
  std::vector<Eigen::Vector3d> pointsAtOrAbove(std::optional<double> min_probability, PointOf point_of) const;
  static uint64_t pack(int x, int y, int z);
  static Eigen::Vector3i unpack(uint64_t key);
  std::optional<uint64_t> keyOf(const Eigen::Vector3d& x_w) const;
  Eigen::Vector3d centreOf(uint64_t key) const;
  bool occupied(const Voxel& v) const;
  void enforceBudget();
  /// The [near, far] depths of the mask's hits (the depth gate).
  std::pair<double, double> depthGate(const DepthImage& depth, const BinaryMask& mask, int stride) const;

  /// The slot of `slots_` that holds `key`, or the empty one where it would go (slots_ not empty).
  size_t slotOf(uint64_t key) const;
  /// The index of the voxel with `key`, or -1 when there is none.
  long indexOf(uint64_t key) const;
  /// The index of the voxel with `key`, created (probability 0.5, no points) when there is none.
  size_t indexOrAdd(uint64_t key, bool* added);
  /// Keeps the voxels for which keep(voxel) is true, in their order, and indexes them again.
  template <class Keep>
  size_t keepIf(Keep keep);
  /// Rebuilds `slots_` for the voxels held, at least `min_slots` long and at most half full.
  void reindex(size_t min_slots);

  VoxelOptions options_;
  float occupied_log_odds_;  // of options_.occupied_probability: occupied() runs once per voxel
  // The voxels in the order they were created (keys_[i] is voxels_[i]'s key), so that the passes
  // over all of them (several per object and keyframe) read memory in sequence, found by key
  // through `slots_`: an open-addressing table (linear probing, a power of two long, at most half
  // full) of index + 1 into them, 0 for an empty slot.
  std::vector<uint64_t> keys_;
  std::vector<Voxel> voxels_;
  std::vector<uint32_t> slots_;
  uint32_t frames_ = 0;
};

/// The mask after a 3x3 majority vote (5 of 9 pixels set), same crop.
BinaryMask majorityFiltered(const BinaryMask& mask);

/// The depth readings within [min_depth, max_depth] under a mask's pixels, of every `stride`-th
/// row and column of its crop (the mask must lie within the depth image).
std::vector<double> maskDepths(const DepthImage& depth, const BinaryMask& mask, int stride, double min_depth,
                               double max_depth);

/// A mask covering a box (the whole box is the object): for detectors without masks.
BinaryMask maskFromBox(const Box& box, int image_width, int image_height);

}  // namespace ellreloc
