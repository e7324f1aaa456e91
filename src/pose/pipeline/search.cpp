#include "search.hpp"

#include <algorithm>
#include <limits>

namespace ellreloc::pipeline {

namespace {

/// The budgets of options.search for this frame.
RansacOptions frameBudget(const SearchOptions& search, HypothesisSampler sampler, size_t num_objects, int num_usable) {
  RansacOptions budget = search.budget;
  // Scoring a hypothesis costs up to (map objects) x (usable observations) overlaps: a large map
  // with many observations gets fewer hypotheses, so that the worst case stays bounded.
  if (search.max_overlap_evaluations > 0) {
    const double per_hypothesis = static_cast<double>(num_objects) * static_cast<double>(num_usable);
    const long affordable = static_cast<long>(static_cast<double>(search.max_overlap_evaluations) / per_hypothesis);
    budget.max_hypotheses = std::min(budget.max_hypotheses, std::max(affordable, search.min_hypotheses));
  }
  if (sampler == HypothesisSampler::Exhaustive) {  // try everything: only hypotheses and time bound it
    budget.min_iterations = std::numeric_limits<int>::max() / 2;
    budget.max_iterations = std::numeric_limits<int>::max() / 2;
  }
  return budget;
}

}  // namespace

void searchTriplets(const HypothesisEstimator& estimator, const RelocalizerOptions& options, size_t num_objects,
                    int num_usable, HypothesisPool* pool, SearchOutcome* outcome) {
  const int n = static_cast<int>(estimator.numData());
  HypothesisSampler sampler = options.search.sampler;
  if (sampler == HypothesisSampler::Auto) {
    const double triplets = static_cast<double>(n) * (n - 1) * (n - 2) / 6.0;
    sampler = triplets <= static_cast<double>(options.search.max_exhaustive_triplets) ? HypothesisSampler::Exhaustive
                                                                                      : HypothesisSampler::Prosac;
  }
  const RansacOptions budget = frameBudget(options.search, sampler, num_objects, num_usable);
  const auto remember = [pool](const PoseHypothesis& h, double cost, int) { pool->offer(h.pose, cost); };
  PoseHypothesis best;
  RansacStats stats;
  bool found = false;
  switch (sampler) {
    case HypothesisSampler::Auto:  // resolved above
    case HypothesisSampler::Exhaustive: {
      ExhaustiveSampler s(n, 3);
      found = ransac(estimator, s, budget, &best, &stats, remember);
      break;
    }
    case HypothesisSampler::Uniform: {
      UniformSampler s(n, 3, budget.seed);
      found = ransac(estimator, s, budget, &best, &stats, remember);
      break;
    }
    case HypothesisSampler::Prosac: {
      // Reach uniform sampling over all pairs within ~1000 samples: the MSAC stopping rule
      // assumes samples from all the data, and a wrong early model must not end the search
      // while good pairs of lower quality are still out of reach.
      ProsacSampler s(n, 3, budget.seed, 1000);
      found = ransac(estimator, s, budget, &best, &stats, remember);
      break;
    }
  }
  outcome->found = found;
  outcome->best = best.pose;
  outcome->best_inliers = stats.num_inliers;
  outcome->hypotheses = stats.hypotheses;
  outcome->iterations = stats.iterations;
  outcome->budget_exhausted = stats.budget_exhausted;
}

void searchFewObjects(const HypothesisEstimator& estimator, const Candidates& candidates,
                      const RelocalizerOptions& options, const std::optional<GravityPrior>& gravity,
                      HypothesisPool* pool, SearchOutcome* outcome) {
  const std::vector<CandidatePair>& pairs = candidates.pairs;
  const long max_calls = options.few_objects.max_pair_hypotheses;
  std::vector<PoseHypothesis> poses;
  long calls = 0;
  for (size_t i = 0; i < pairs.size() && calls < max_calls; ++i)
    for (size_t j = i + 1; j < pairs.size() && calls < max_calls; ++j) {
      if (pairs[i].observation == pairs[j].observation || pairs[i].object == pairs[j].object) continue;
      ++calls;
      estimator.fromTwoPairs(static_cast<int>(i), static_cast<int>(j), gravity, &poses);
    }
  if (gravity && candidates.num_usable == 1)
    for (size_t i = 0; i < pairs.size() && calls < max_calls; ++i, ++calls)
      estimator.fromOnePair(static_cast<int>(i), *gravity, &poses);
  // They compete with the triplets' poses in the same score.
  for (const PoseHypothesis& h : poses) {
    int inliers = 0;
    pool->offer(h.pose, estimator.score(h, &inliers));
  }
  outcome->few_object_hypotheses = static_cast<long>(poses.size());
  outcome->hypotheses += outcome->few_object_hypotheses;
  if (!poses.empty()) outcome->found = true;
  if (!pool->empty()) outcome->best = pool->best().pose;
}

}  // namespace ellreloc::pipeline
