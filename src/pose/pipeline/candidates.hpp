#pragma once
// Which map objects each observation may be: the first step of the relocalization pipeline.

#include <string>
#include <utility>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/object_map.hpp"
#include "ellreloc/core/observation.hpp"
#include "ellreloc/pose/pose_region.hpp"
#include "ellreloc/pose/relocalizer_options.hpp"

namespace ellreloc::pipeline {

/// An observation and a map object it may be, before any pose.
struct CandidatePair {
  int observation;
  int object;
  double quality;  // label share x detection score x apparent object size: PROSAC order
};

/// Usable observations and their candidate objects (same category, or a share of the object's
/// label histogram).
struct Candidates {
  std::vector<char> usable;                      // per observation
  std::vector<std::vector<int>> of_observation;  // candidate objects of each observation
  std::vector<CandidatePair> pairs;              // best (PROSAC) first
  int num_usable = 0;
};

/// The indices of `observations` in a canonical order: detection score, highest first, then
/// category, box, ellipse and the rest of the observation (NaN last). The relocalizer works on
/// the observations in this order, so that its result does not depend on the order a detector
/// lists its detections in: ties among near-equal hypotheses are settled by it.
std::vector<int> canonicalOrder(const std::vector<Observation>& observations);

/// Triplets of pairs with three distinct observations: the triplets P3P is tried on (a triplet
/// that repeats an object is dropped when generated). Counted, not enumerated.
double usableTriplets(const Candidates& candidates);

/// Observations that are invalid, have no candidate object, or would take the pairs beyond
/// max_pairs go to `skipped` (in observation order) with the reason.
Candidates collectCandidates(const std::vector<Observation>& observations, const ObjectMap& map,
                             const ScoringOptions& options, long max_pairs,
                             std::vector<std::pair<int, std::string>>* skipped);

/// The pairs a triplet search draws from inside a pose region: those whose object can lie on its
/// observation's bearing (the ray through the ellipse's centre, as P3P takes it) from some camera
/// in the region. From a camera within the region's radius r of its centre, an object at distance
/// D > r from that centre lies within asin(r / D) of its direction from there, and a camera
/// turned by at most the region's angle sees that direction at most that angle off: a pair whose
/// bearing is farther from where the region's pose sees its object gives only P3P poses outside
/// the region, which the gate drops before anything else. Such pairs leave `pairs` and
/// `of_observation`; `usable` and `num_usable` are kept, so that scoring counts every observation
/// as before. Without an angle bound no pair is removed.
Candidates candidatesWithinRegion(const Candidates& candidates, const std::vector<Observation>& observations,
                                  const ObjectMap& map, const Intrinsics& K, const PoseRegion& region);

}  // namespace ellreloc::pipeline
