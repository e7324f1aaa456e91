#pragma once
// The search stage: hypotheses from triplets (RANSAC over P3P) and, for frames with few
// observations, from pairs and single pairs with gravity. Every scored hypothesis is offered to
// the pool.

#include <optional>

#include "hypothesis_estimator.hpp"
#include "hypothesis_pool.hpp"

namespace ellreloc::pipeline {

struct SearchOutcome {
  bool found = false;
  Pose best;             // the lowest-cost hypothesis
  int best_inliers = 0;  // its match count (triplet search)
  long hypotheses = 0;
  long few_object_hypotheses = 0;
  int iterations = 0;
  bool budget_exhausted = false;
};

/// RANSAC over triplets of candidate pairs with the sampler and budgets of options.search.
void searchTriplets(const HypothesisEstimator& estimator, const RelocalizerOptions& options, size_t num_objects,
                    int num_usable, HypothesisPool* pool, SearchOutcome* outcome);

/// The two-object solver on pairs of candidate pairs, and with gravity and a single usable
/// observation, the one-object solver; up to few_objects.max_pair_hypotheses solver calls.
void searchFewObjects(const HypothesisEstimator& estimator, const Candidates& candidates,
                      const RelocalizerOptions& options, const std::optional<GravityPrior>& gravity,
                      HypothesisPool* pool, SearchOutcome* outcome);

}  // namespace ellreloc::pipeline
