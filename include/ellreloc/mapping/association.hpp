#pragma once
/// \file association.hpp
/// Object tracking of the paper ("Objects Tracking"): 2D association of map objects with a
/// keyframe's detections, and 3D matching of the detections left over against the map.
///
/// 2D: each map object's voxels are projected into the keyframe and give a box (the mapper's
/// objects in the map project only those near their ellipsoid); the cost of
/// pairing object i with detection j is (eqs. 2-3, f read as a label mismatch cost)
///     cost(i, j) = lambda1 [label_i != label_j] + lambda2 (1 - IoU(box_i, box_j)),
/// lambda1 >> lambda2, solved by the Hungarian method; a pair is kept only when its boxes
/// overlap enough (a gate), and with different labels only when they overlap strongly.
/// 3D: a detection's own voxels v match map object v_i of its label when (eq. 4)
///     n(v, v_i) > xi min(|v|, |v_i|)  and  n(v_i, v) > xi min(|v|, |v_i|),
/// n(a, b) = voxels of a with a voxel of b within radius r.

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "ellreloc/core/box.hpp"
#include "ellreloc/mapping/hungarian.hpp"
#include "ellreloc/mapping/voxel_object.hpp"

namespace ellreloc {

struct TrackingOptions {
  double label_weight = 10.0;  ///< lambda1
  double iou_weight = 1.0;     ///< lambda2
  double min_iou = 0.2;        ///< 2D gate: pairs with less overlap are not associated
  /// A detection whose label differs from the object's joins it only with this much overlap
  /// (detectors confuse labels; the object's label is the most frequent one).
  double min_iou_other_label = 0.5;
  /// Voxel mode, detections with a mask: the median depth of the mask's pixels must lie within
  /// the object's depth range in the keyframe, widened by this much (metres), for 2D tracking to
  /// pair them: two objects one behind the other overlap in the image, not in depth.
  double depth_margin = 0.1;
  double match_radius = 0.05;  ///< r of eq. 4, metres
  double match_ratio = 0.5;    ///< xi of eq. 4
};

/// A box with a label: a map object's projection or a detection.
struct LabelledBox {
  Box box;
  int label = 0;
  /// A map object's other possible boxes (where an object whose depth is not known yet would
  /// appear at other depths): its overlap with a detection is the best of all its boxes.
  std::vector<Box> alternatives;
};

/// Which object-detection pairs 2D association may keep (objects x detections); empty: all.
using PairGate = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>;

/// 2D association: for each detection, the index of its map object or -1. Pairs the gate rules
/// out are never kept.
inline std::vector<int> associateBoxes(const std::vector<LabelledBox>& objects,
                                       const std::vector<LabelledBox>& detections, const TrackingOptions& options = {},
                                       const PairGate& gate = {}) {
  std::vector<int> result(detections.size(), -1);
  if (objects.empty() || detections.empty()) return result;
  Eigen::MatrixXd cost(static_cast<long>(objects.size()), static_cast<long>(detections.size()));
  Eigen::MatrixXd iou(cost.rows(), cost.cols());
  for (size_t i = 0; i < objects.size(); ++i)
    for (size_t j = 0; j < detections.size(); ++j) {
      double o = boxIoU(objects[i].box, detections[j].box);
      for (const Box& b : objects[i].alternatives) o = std::max(o, boxIoU(b, detections[j].box));
      const bool other_label = objects[i].label != detections[j].label;
      const bool ruled_out = gate.size() > 0 && !gate(static_cast<long>(i), static_cast<long>(j));
      iou(static_cast<long>(i), static_cast<long>(j)) = ruled_out ? 0.0 : o;
      // A pair ruled out costs more than any other, so the assignment takes as few as it can.
      cost(static_cast<long>(i), static_cast<long>(j)) =
          ruled_out ? 2.0 * (options.label_weight + options.iou_weight)
                    : options.label_weight * (other_label ? 1.0 : 0.0) + options.iou_weight * (1.0 - o);
    }
  const std::vector<int> assignment = hungarianAssignment(cost);
  for (size_t i = 0; i < objects.size(); ++i) {
    const int j = assignment[i];
    if (j < 0) continue;
    const double o = iou(static_cast<long>(i), j);
    const bool other_label = objects[i].label != detections[static_cast<size_t>(j)].label;
    if (o >= (other_label ? options.min_iou_other_label : options.min_iou))
      result[static_cast<size_t>(j)] = static_cast<int>(i);
  }
  return result;
}

/// How well a detection's voxels `v` match a map object's voxels `vi`: the smaller of n(v, v_i)
/// and n(v_i, v) over min(|v|, |v_i|) (0 when either is empty), which eq. 4 compares with xi.
inline double voxelMatchStrength(const VoxelObject& v, const VoxelObject& vi, const TrackingOptions& options = {}) {
  const double smaller = static_cast<double>(std::min(v.occupiedCount(), vi.occupiedCount()));
  if (smaller <= 0.0) return 0.0;
  return static_cast<double>(std::min(v.countNear(vi, options.match_radius), vi.countNear(v, options.match_radius))) /
         smaller;
}

/// 3D matching (eq. 4) of a detection's voxels `v` with a map object's voxels `vi`.
inline bool voxelObjectsMatch(const VoxelObject& v, const VoxelObject& vi, const TrackingOptions& options = {}) {
  return voxelMatchStrength(v, vi, options) > options.match_ratio;
}

}  // namespace ellreloc
