#pragma once
// The search stage: hypotheses from triplets (RANSAC over P3P) and, for frames with few
// observations, from pairs and single pairs with gravity. Every scored hypothesis is offered to
// the pool.

#include <chrono>
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

/// One frame's work budget, shared by every search stage: hypotheses, and wall-clock time
/// counted from the start of the frame.
struct FrameBudget {
  long max_hypotheses = 0;
  double max_time_ms = 0.0;  // 0: none
  std::chrono::steady_clock::time_point start;

  double elapsedMs() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  bool timeUp() const { return max_time_ms > 0.0 && elapsedMs() >= max_time_ms; }
};

/// The budget of options.search for a frame: search.budget.max_hypotheses, shrunk so that at
/// most search.max_overlap_evaluations overlaps are scored (a hypothesis costs up to one per
/// map object and usable observation), and search.budget.max_time_ms from `start`.
FrameBudget frameBudget(const SearchOptions& search, size_t num_objects, int num_usable,
                        std::chrono::steady_clock::time_point start);

/// RANSAC over triplets of `candidates`' pairs with the sampler of options.search, within
/// `budget`, on one thread per estimator (equivalent estimators over those candidates, each with
/// its own scorer).
void searchTriplets(const std::vector<const HypothesisEstimator*>& estimators, const Candidates& candidates,
                    const RelocalizerOptions& options, const FrameBudget& budget, HypothesisPool* pool,
                    SearchOutcome* outcome);

/// The two-object solver on pairs of candidate pairs, and with gravity and a single usable
/// observation, the one-object solver: up to few_objects.max_pair_hypotheses solver calls, and
/// no more hypotheses or time than `budget` leaves after the triplets. The two-object sweep keeps
/// to the `region`'s angle.
void searchFewObjects(const HypothesisEstimator& estimator, const Candidates& candidates,
                      const RelocalizerOptions& options, const std::optional<GravityPrior>& gravity,
                      const std::optional<PoseRegion>& region, const FrameBudget& budget, HypothesisPool* pool,
                      SearchOutcome* outcome);

}  // namespace ellreloc::pipeline
