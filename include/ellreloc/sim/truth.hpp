#pragma once
/// \file truth.hpp
/// What an observation should have been, for scoring observation ellipses and regular-mask
/// verdicts: per detection of a rendered frame, the object it shows, the projection of that
/// object's ellipsoid (the one inscribed in its cuboid) under the true pose, and whether its
/// noise-free visible mask outlines a convex quadrilateral (the paper's "regular" object).

#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/rle.hpp"
#include "ellreloc/sim/render.hpp"
#include "ellreloc/sim/scene.hpp"

namespace ellreloc::sim {

/// True when the outer outline of the mask, reduced by Douglas-Peucker to within 2% of its
/// perimeter, is a convex quadrilateral: one face of a box, not two or three, nor a blob.
/// The verdict the paper's regular test should give on the mask without noise.
bool outlineIsConvexQuadrilateral(const RleMask& clean_mask);

/// The truth of each detection that shows an object (`object_id` set; false positives have
/// none): a copy with the same box, the object's category and id, `ellipse` = the projection
/// of its ellipsoid with `pose` (left empty when there is none) and `regular` from the frame's
/// noise-free mask. Written by writeSimulation as ellipse_truth.json (the detections format).
std::vector<Detection> detectionTruth(const Scene& scene, const RenderedFrame& frame, const Intrinsics& K,
                                      const Pose& pose, const std::vector<Detection>& detections);

}  // namespace ellreloc::sim
