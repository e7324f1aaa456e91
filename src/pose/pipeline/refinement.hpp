#pragma once
// The refinement stage: the best distinct hypotheses refined with the Wasserstein refiner on
// all their matches, and optionally with the frame's keypoints.

#include <limits>
#include <optional>
#include <vector>

#include "hypothesis_estimator.hpp"
#include "hypothesis_pool.hpp"
#include "pose_scorer.hpp"

namespace ellreloc::pipeline {

/// A pose with its cost and matches under the scorer (at kReportIoUVertices).
struct ChosenPose {
  Pose pose;
  double cost = 0.0;
  std::vector<ObjectCorrespondence> matches;
  bool refined = false;
  /// The other answers the refined starts reached, cheapest first, each kValidPositionCm or
  /// kValidRotationDeg away from this pose and from every cheaper one; the cost of the first
  /// less this pose's (infinity when there is none).
  std::vector<ScoredPose> alternatives;
  double margin = std::numeric_limits<double>::infinity();
};

/// What refinement needs besides the pool and the scorer.
struct RefinementContext {
  const std::vector<Observation>& observations;
  const ObjectMap& map;
  const Intrinsics& K;
  const RelocalizerOptions& options;
  const std::optional<GravityPrior>& gravity;
  PoseGate gate;
};

/// Refines `start` on its matches, matches again at the refined pose, and repeats while that
/// explains the observations better (a refined pose often brings more objects into overlap).
ChosenPose refineRounds(const Pose& start, PoseScorer& scorer, const RefinementContext& context);

/// Starts from `search_best` (the search's best pose) and refines the pooled hypotheses within
/// refinement.cost_margin of the pool's best, at most `max_refined`, best first; returns the
/// lowest-cost result, with the other answers the refined starts reached and its margin over
/// the best of them. The refinements run on one thread per scorer (the same result).
ChosenPose refineHypotheses(const HypothesisPool& pool, const Pose& search_best,
                            const std::vector<PoseScorer*>& scorers, const RefinementContext& context,
                            size_t max_refined);

/// Refines the chosen pose once more on its matches with the tighter loss of
/// refinement.polish_loss_scale; keeps the result when it costs no more and stays in the gate.
ChosenPose polishPose(ChosenPose chosen, PoseScorer& scorer, const RefinementContext& context);

/// Refines the chosen pose again with keypoints matched to map points; keeps the result when it
/// still explains as many observations.
ChosenPose refineWithPoints(ChosenPose chosen, const std::vector<PointMatch>& points, PoseScorer& scorer,
                            const RefinementContext& context);

/// The ellipse-ellipsoid pairs of a list of matches, for the refiner: ellipses fitted to regular
/// masks with the sigma of the options (RefinementStageOptions::regular_mask_sigma).
std::vector<EllipseMatch> ellipseMatches(const std::vector<ObjectCorrespondence>& matches,
                                         const RefinementContext& context);

}  // namespace ellreloc::pipeline
