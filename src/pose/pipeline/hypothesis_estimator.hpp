#pragma once
// Pose hypotheses from minimal samples of candidate pairs: P3P on three (the RANSAC estimator),
// the two-object solver on two, one object and gravity on one. Every pose is checked the same
// way (gravity gate, its own objects in view and overlapping their observations) and carries
// the projections of its own objects, so scoring does not project them again.

#include <optional>
#include <vector>

#include "candidates.hpp"
#include "ellreloc/core/camera.hpp"
#include "ellreloc/pose/gravity_prior.hpp"
#include "ellreloc/pose/pose_region.hpp"
#include "ellreloc/pose/relocalizer_options.hpp"
#include "hypothesis_pool.hpp"
#include "pose_scorer.hpp"

namespace ellreloc::pipeline {

/// Drops poses that tilt the camera more than max(gate_deg, 5 sigma) away from a gravity prior,
/// and poses outside the camera envelope or the frame's pose region.
struct PoseGate {
  std::optional<GravityPrior::Bound> gravity;        // none: any tilt
  std::optional<CameraEnvelope::Prepared> envelope;  // none: anywhere
  std::optional<PoseRegion::Prepared> region;        // none: anywhere
  bool admits(const Pose& pose) const {
    return (!gravity || gravity->admits(pose)) && (!envelope || envelope->admits(pose)) &&
           (!region || region->admits(pose));
  }
};

/// A pose that explains all of a frame's usable observations explains them well at this cost or
/// below (a mean credit of search.explained_mean_credit): it ends a sampled search
/// (stop_when_explained), and one above it is refined (refine_explained). Neither applies below
/// kMinExplainedObservations, where a pose's own sample is most of what it explains.
constexpr int kMinExplainedObservations = 4;
inline double explainedCost(const SearchOptions& search, int num_usable) {
  return num_usable * (1.0 - search.explained_mean_credit);
}

/// The sampler a frame's triplet search uses: options.search.sampler, Auto resolved by the
/// number of usable triplets (at most max_exhaustive_triplets: Exhaustive, else Prosac).
HypothesisSampler frameSampler(const Candidates& candidates, const SearchOptions& search);

/// The pair the refiner reads for a match: an ellipse fitted to a regular mask weighs by
/// `regular_mask_sigma` (RefinementStageOptions), any other ellipse by 1.
EllipseMatch refinerMatch(const Observation& o, const Ellipsoid& e, const RefinementStageOptions& options);

/// A hypothesis: a pose and its own objects' projections at it.
struct PoseHypothesis {
  Pose pose;
  KnownProjections own;
};

class HypothesisEstimator {
 public:
  using Model = PoseHypothesis;
  static constexpr int kSampleSize = 3;
  static constexpr int kMaxModels = 4;

  /// With a `pool`, score() gives up on a pose as soon as bounds show that it could not enter
  /// the pool (infinite cost): such a pose changes nothing, so the search's result is the same.
  HypothesisEstimator(const std::vector<Observation>& observations, const Candidates& candidates, const ObjectMap& map,
                      const Intrinsics& K, const RelocalizerOptions& options, const PoseGate& gate, PoseScorer& scorer,
                      const HypothesisPool* pool = nullptr)
      : observations_(observations),
        pairs_(candidates.pairs),
        map_(map),
        K_(K),
        options_(options),
        gate_(gate),
        scorer_(scorer),
        pool_(pool),
        num_usable_(candidates.num_usable),
        sampled_(frameSampler(candidates, options.search) != HypothesisSampler::Exhaustive) {}

  // The RANSAC estimator concept (core/ransac.hpp) over candidate pairs.
  size_t numData() const { return pairs_.size(); }
  /// P3P on the observed centres of three pairs, with the projected-centre correction.
  int generate(const int* sample, Model* models) const;
  /// The ranking cost (PoseScorer::cost at kRankingIoUVertices).
  double score(const Model& model, int* num_inliers) const;
  /// Local optimisation (search.refine_explained): a model of `cost` below `admission` (the
  /// pool's) whose `num_inliers` matches explain every usable observation, at least four, with a
  /// mean credit below search.explained_mean_credit is refined on its matches, and replaced by
  /// the refined pose when that scores lower; returns the model's cost, `num_inliers` updated.
  /// Called where the pool is current (in sample order), so that the search's result does not
  /// depend on its thread count: a scorer on another thread may have read an older admission.
  double refineIfLoose(Model* model, double cost, int* num_inliers, double admission) const;

  /// Poses from two candidate pairs (two-object solver, its sweep kept to the region's angle),
  /// checked like P3P's; appended to `out`.
  void fromTwoPairs(int a, int b, const std::optional<GravityPrior>& gravity, const std::optional<PoseRegion>& region,
                    std::vector<Model>* out) const;
  /// Poses from one candidate pair and gravity; appended to `out`.
  void fromOnePair(int a, const GravityPrior& gravity, std::vector<Model>* out) const;

 private:
  /// The gate, then every own pair in view and, with `check_overlap`, overlapping its
  /// observation by scoring.min_overlap; fills `own`.
  bool accept(const Pose& pose, const int* pair_indices, int count, bool check_overlap, KnownProjections* own) const;
  /// Whether each of a sample's three objects may image large or small enough to overlap its
  /// observation by scoring.min_overlap (PoseScorer::sizeMayReach).
  bool ownSizesMayFit(const Pose& pose, const int* sample) const;
  bool correctCentres(const int* pair_indices, Pose* pose) const;
  /// search.uncorrected_when_closer: `model` (a P3P pose) or its centre correction, whichever
  /// passes the sample check and fits the sample's own observations closer; false when neither
  /// passes.
  bool correctedOrNot(const int* sample, Model* model) const;
  /// The sum over a sample's own pairs of W2^2 over the observed ellipse's axes product.
  double ownFit(const int* sample, const KnownProjections& own) const;
  void fromSolver(const std::vector<ScoredPose>& poses, const int* pair_indices, int count,
                  std::vector<Model>* out) const;

  const std::vector<Observation>& observations_;
  const std::vector<CandidatePair>& pairs_;
  const ObjectMap& map_;
  const Intrinsics& K_;
  const RelocalizerOptions& options_;
  PoseGate gate_;
  PoseScorer& scorer_;
  const HypothesisPool* pool_;
  int num_usable_;
  bool sampled_;  // the frame's triplets are sampled, not enumerated
};

}  // namespace ellreloc::pipeline
