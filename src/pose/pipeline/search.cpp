#include "search.hpp"

#include <algorithm>
#include <limits>

namespace ellreloc::pipeline {

FrameBudget frameBudget(const SearchOptions& search, size_t num_objects, int num_usable,
                        std::chrono::steady_clock::time_point start) {
  FrameBudget budget;
  budget.max_hypotheses = search.budget.max_hypotheses;
  budget.max_time_ms = search.budget.max_time_ms;
  budget.start = start;
  if (search.max_overlap_evaluations > 0) {
    const double per_hypothesis = std::max(1.0, static_cast<double>(num_objects) * static_cast<double>(num_usable));
    const double affordable = static_cast<double>(search.max_overlap_evaluations) / per_hypothesis;
    budget.max_hypotheses = std::min(budget.max_hypotheses, static_cast<long>(affordable));
  }
  return budget;
}

void searchTriplets(const std::vector<const HypothesisEstimator*>& estimators, const Candidates& candidates,
                    const RelocalizerOptions& options, const FrameBudget& frame, HypothesisPool* pool,
                    SearchOutcome* outcome) {
  const int n = static_cast<int>(estimators.front()->numData());
  const HypothesisSampler sampler = frameSampler(candidates, options.search);
  RansacOptions budget = options.search.budget;
  budget.max_hypotheses = frame.max_hypotheses;
  if (frame.max_time_ms > 0.0) {  // what the frame's clock has left (0 would mean no bound)
    budget.max_time_ms = frame.max_time_ms - frame.elapsedMs();
    if (budget.max_time_ms <= 0.0) budget.max_hypotheses = 0, budget.max_time_ms = 1e-9;
  }
  // The adaptive count reads a pose's inliers over every candidate pair: with twelve look-alike
  // candidates per observation it asks for as many samples as if at most one pair in twelve
  // could be right, even once a pose explains every observation, which no pose can exceed. Such
  // a pose (explainedCost) ends a sampled search; the enough_* fields are the relocalizer's, set
  // here per frame.
  budget.enough_inliers = std::numeric_limits<int>::max();
  budget.enough_score = -std::numeric_limits<double>::infinity();
  if (sampler != HypothesisSampler::Exhaustive && options.search.stop_when_explained &&
      candidates.num_usable >= kMinExplainedObservations) {
    budget.enough_inliers = candidates.num_usable;
    budget.enough_score = explainedCost(options.search, candidates.num_usable);
  }
  if (sampler == HypothesisSampler::Exhaustive) {  // try everything: only hypotheses and time bound it
    budget.min_iterations = std::numeric_limits<int>::max() / 2;
    budget.max_iterations = std::numeric_limits<int>::max() / 2;
    budget.skip_repeated_samples = false;  // an enumeration repeats nothing
  }
  // In sample order on this thread, where the pool is current: a loose hypothesis that explains
  // every observation is refined first (estimators.front()'s scorer is idle meanwhile).
  const HypothesisEstimator& local = *estimators.front();
  const auto remember = [pool, &local](PoseHypothesis& h, double& cost, int& inliers) {
    cost = local.refineIfLoose(&h, cost, &inliers, pool->admissionCost());
    pool->offer(h.pose, cost);
  };
  PoseHypothesis best;
  RansacStats stats;
  bool found = false;
  switch (sampler) {
    case HypothesisSampler::Auto:  // resolved above
    case HypothesisSampler::Exhaustive: {
      ExhaustiveSampler s(n, 3);
      found = ransacOnThreads(estimators, s, budget, &best, &stats, remember);
      break;
    }
    case HypothesisSampler::Uniform: {
      UniformSampler s(n, 3, budget.seed);
      found = ransacOnThreads(estimators, s, budget, &best, &stats, remember);
      break;
    }
    case HypothesisSampler::Prosac: {
      // Reach uniform sampling over all pairs within ~1000 samples: the MSAC stopping rule
      // assumes samples from all the data, and a wrong early model must not end the search
      // while good pairs of lower quality are still out of reach.
      ProsacSampler s(n, 3, budget.seed, 1000);
      found = ransacOnThreads(estimators, s, budget, &best, &stats, remember);
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
                      const std::optional<PoseRegion>& region, const FrameBudget& budget, HypothesisPool* pool,
                      SearchOutcome* outcome) {
  const std::vector<CandidatePair>& pairs = candidates.pairs;
  const long max_calls = options.few_objects.max_pair_hypotheses;
  const long max_poses = std::max(0L, budget.max_hypotheses - outcome->hypotheses);
  std::vector<PoseHypothesis> poses;
  long calls = 0;
  // A solver call costs far more than a clock read: the clock is read before each.
  const auto more = [&] {
    if (calls >= max_calls || static_cast<long>(poses.size()) >= max_poses) return false;
    if (budget.timeUp()) return outcome->budget_exhausted = true, false;
    return true;
  };
  for (size_t i = 0; i < pairs.size() && more(); ++i)
    for (size_t j = i + 1; j < pairs.size() && more(); ++j) {
      if (pairs[i].observation == pairs[j].observation || pairs[i].object == pairs[j].object) continue;
      ++calls;
      estimator.fromTwoPairs(static_cast<int>(i), static_cast<int>(j), gravity, region, &poses);
    }
  if (gravity && candidates.num_usable == 1)
    for (size_t i = 0; i < pairs.size() && more(); ++i, ++calls)
      estimator.fromOnePair(static_cast<int>(i), *gravity, &poses);
  if (static_cast<long>(poses.size()) > max_poses) {  // a solver call may give several
    poses.resize(static_cast<size_t>(max_poses));
    outcome->budget_exhausted = true;
  }
  // They compete with the triplets' poses in the same score.
  for (PoseHypothesis& h : poses) {
    int inliers = 0;
    double cost = estimator.score(h, &inliers);
    cost = estimator.refineIfLoose(&h, cost, &inliers, pool->admissionCost());
    pool->offer(h.pose, cost);
  }
  outcome->few_object_hypotheses = static_cast<long>(poses.size());
  outcome->hypotheses += outcome->few_object_hypotheses;
  if (!poses.empty()) outcome->found = true;
  if (!pool->empty()) outcome->best = pool->best().pose;
}

}  // namespace ellreloc::pipeline
