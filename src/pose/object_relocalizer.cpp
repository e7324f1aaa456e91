#include "ellreloc/pose/object_relocalizer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "ellreloc/error.hpp"
#include "pipeline/candidates.hpp"
#include "pipeline/hypothesis_estimator.hpp"
#include "pipeline/hypothesis_pool.hpp"
#include "pipeline/pose_scorer.hpp"
#include "pipeline/refinement.hpp"
#include "pipeline/search.hpp"

namespace ellreloc {

using namespace pipeline;

const char* toString(RelocalizationStatus s) {
  switch (s) {
    case RelocalizationStatus::Success:
      return "success";
    case RelocalizationStatus::NotEnoughObservations:
      return "not enough observations";
    case RelocalizationStatus::NoConsistentHypothesis:
      return "no consistent hypothesis";
    case RelocalizationStatus::InvalidInput:
      return "invalid input";
    case RelocalizationStatus::LowEvidence:
      return "low evidence";
  }
  return "unknown";
}

namespace {

/// The matches of a pose as the result's correspondences, their mean overlap and the evidence
/// they give among `usable` observations.
void reportMatches(const std::vector<ObjectCorrespondence>& matches, int usable, const AcceptanceOptions& acceptance,
                   RelocalizationResult* result) {
  double sum = 0.0;
  for (const ObjectCorrespondence& m : matches) sum += m.overlap;
  result->inliers = matches;
  result->mean_overlap = matches.empty() ? 0.0 : sum / static_cast<double>(matches.size());
  result->evidence = matchEvidence(matches, usable, acceptance);
}

/// Keypoints whose index names a finite map point, as the refiner's point matches.
std::vector<PointMatch> pointMatches(const std::vector<Keypoint>& keypoints, const ObjectMap& map) {
  std::vector<PointMatch> points;
  for (const Keypoint& k : keypoints)
    if (k.point_index >= 0 && static_cast<size_t>(k.point_index) < map.points.size() && k.uv.allFinite() &&
        map.points[static_cast<size_t>(k.point_index)].allFinite())
      points.push_back({k.uv, map.points[static_cast<size_t>(k.point_index)]});
  return points;
}

/// Why the input cannot be relocalized at all, or empty.
std::string invalidInput(const ObjectMap& map, const Intrinsics& K, const std::optional<GravityPrior>& gravity,
                         const std::optional<PoseRegion>& region, const RelocalizerOptions& options) {
  if (!K.isValid()) return "invalid intrinsics";
  if (!validUnitMetres(map.unit_metres)) return "invalid map unit_metres (not a length of 1e-6 to 1e6 metres)";
  if (gravity && !gravity->isValid())
    return "invalid gravity prior (zero or non-finite direction, or sigma not positive)";
  if (region && !region->isValid())
    return "invalid pose region (non-finite pose, radius not positive, or angle outside (0, 180] degrees)";
  const std::string bad_option = options.validate();
  return bad_option.empty() ? "" : "invalid options: " + bad_option;
}

/// What every hypothesis of a frame must pass, prepared once: a tilt within max(gate_deg, 5
/// sigma) of the gravity prior, the camera envelope and the pose region.
PoseGate frameGate(const std::optional<GravityPrior>& gravity, const std::optional<PoseRegion>& region,
                   const RelocalizerOptions& options) {
  PoseGate gate;
  if (gravity) gate.gravity = gravity->bound(std::max(options.gravity.gate_deg, 5.0 * gravity->sigma_deg));
  if (options.envelope) gate.envelope = options.envelope->prepared();
  if (region) gate.region = region->prepared();
  return gate;
}

/// Stage 2's triplet search, its samples split over the threads of `scorers` (one estimator on
/// each).
struct TripletSearch {
  const std::vector<Observation>& observations;
  const ObjectMap& map;
  const Intrinsics& K;
  const RelocalizerOptions& options;
  const PoseGate& gate;
  const FrameBudget& budget;
  void run(const Candidates& candidates, const std::vector<PoseScorer*>& scorers, HypothesisPool* pool,
           SearchOutcome* search) const {
    std::vector<HypothesisEstimator> estimators;
    estimators.reserve(scorers.size());
    std::vector<const HypothesisEstimator*> on_threads;
    for (PoseScorer* s : scorers) {
      estimators.emplace_back(observations, candidates, map, K, options, gate, *s, pool);
      on_threads.push_back(&estimators.back());
    }
    searchTriplets(on_threads, candidates, options, budget, pool, search);
  }
};

/// The host's last tracked pose is a hypothesis too: when the camera has barely moved since, it
/// refines to the answer even where no triplet's pose does. One that matches nothing has nothing
/// to refine on and is no answer.
void offerRegionPose(const HypothesisEstimator& estimator, const Pose& pose, HypothesisPool* pool,
                     SearchOutcome* search) {
  PoseHypothesis h{pose, {}};
  int inliers = 0;
  const double cost = estimator.score(h, &inliers);  // infinite when it could not enter the pool
  if (!std::isfinite(cost) || inliers == 0) return;
  pool->offer(h.pose, cost);
  ++search->hypotheses;
  search->found = true;
  search->best = pool->best().pose;
}

/// The observations in the canonical order (canonicalOrder) and that order: `order[k]` is the
/// index in the order given of the k-th.
struct CanonicalFrame {
  std::vector<int> order;
  std::vector<Observation> observations;
};

CanonicalFrame inCanonicalOrder(const std::vector<Observation>& given) {
  CanonicalFrame frame{canonicalOrder(given), {}};
  frame.observations.reserve(given.size());
  for (const int i : frame.order) frame.observations.push_back(given[static_cast<size_t>(i)]);
  return frame;
}

/// `result` with its observation indices (of the canonical order) as indices of the order given.
RelocalizationResult inGivenOrder(RelocalizationResult result, const std::vector<int>& order) {
  for (ObjectCorrespondence& m : result.inliers) m.observation = order[static_cast<size_t>(m.observation)];
  for (auto& [index, reason] : result.skipped) index = order[static_cast<size_t>(index)];
  std::stable_sort(result.skipped.begin(), result.skipped.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  return result;
}

}  // namespace

ObjectRelocalizer::ObjectRelocalizer(ObjectMap map, const Intrinsics& K, RelocalizerOptions options)
    : map_(std::move(map)), K_(K), options_(std::move(options)) {
  options_.few_objects.solver.unit_metres = map_.unit_metres;
  if (!options_.envelope && options_.map_envelope) {
    if (map_.camera_envelope && map_.camera_envelope->isValid()) {
      options_.envelope = map_.camera_envelope;
    } else if ((up_from_objects_ = estimateMapUp(map_))) {
      // Never upside down, and the horizon within 45 degrees of level: hand-held and robot
      // cameras keep their roll within 12 degrees on every real sequence at hand, and the
      // objects' up lies within 9 degrees of the vertical.
      options_.envelope = CameraEnvelope::upright(up_from_objects_->up, 90.0, 45.0);
    }
  }
  for (const MapObject& o : map_.objects)
    if (const std::string problem = mapObjectProblem(o, map_.unit_metres); !problem.empty())
      left_out_.push_back("object " + std::to_string(o.id) + ": " + problem);
}

RelocalizationResult ObjectRelocalizer::scorePose(const std::vector<Observation>& observations,
                                                  const Pose& pose) const {
  const CanonicalFrame frame = inCanonicalOrder(observations);
  return inGivenOrder(scorePoseInOrder(frame.observations, pose), frame.order);
}

RelocalizationResult ObjectRelocalizer::refineFrom(const std::vector<Observation>& observations,
                                                   const Pose& start) const {
  const CanonicalFrame frame = inCanonicalOrder(observations);
  return inGivenOrder(refineFromInOrder(frame.observations, start), frame.order);
}

RelocalizationResult ObjectRelocalizer::scorePoseInOrder(const std::vector<Observation>& observations,
                                                         const Pose& pose) const {
  RelocalizationResult result;
  result.pose = pose;
  const std::string invalid = invalidInput(map_, K_, std::nullopt, std::nullopt, options_);
  if (!invalid.empty() || !pose.isValid()) {
    result.status = RelocalizationStatus::InvalidInput;
    result.reason = invalid.empty() ? "invalid pose" : invalid;
    return result;
  }
  const Candidates candidates =
      collectCandidates(observations, map_, options_.scoring, options_.search.max_candidate_pairs, &result.skipped);
  PoseScorer scorer(observations, candidates, map_, K_, options_.scoring);
  std::vector<ObjectCorrespondence> matches;
  result.cost = scorer.cost(pose, kReportIoUVertices, &matches);
  reportMatches(matches, candidates.num_usable, options_.acceptance, &result);
  const int needed = std::min(options_.scoring.min_inliers, std::max(candidates.num_usable, 1));
  const bool enough = static_cast<int>(matches.size()) >= needed;
  result.status = enough ? RelocalizationStatus::Success : RelocalizationStatus::NoConsistentHypothesis;
  if (!enough) result.reason = "the pose explains " + std::to_string(matches.size()) + " observation(s)";
  return result;
}

RelocalizationResult ObjectRelocalizer::refineFromInOrder(const std::vector<Observation>& observations,
                                                          const Pose& start) const {
  if (!invalidInput(map_, K_, std::nullopt, std::nullopt, options_).empty() || !start.isValid())
    return scorePoseInOrder(observations, start);  // says why
  std::vector<std::pair<int, std::string>> skipped;
  const Candidates candidates =
      collectCandidates(observations, map_, options_.scoring, options_.search.max_candidate_pairs, &skipped);
  PoseScorer scorer(observations, candidates, map_, K_, options_.scoring);
  const std::optional<GravityPrior> no_gravity;
  const RefinementContext context{observations, map_, K_, options_, no_gravity, PoseGate{}};
  const ChosenPose refined = refineRounds(start, scorer, context);
  RelocalizationResult result = scorePoseInOrder(observations, refined.pose);
  result.refined = refined.refined;
  return result;
}

std::vector<EllipseMatch> ObjectRelocalizer::refinementMatches(const std::vector<Observation>& observations,
                                                               const std::vector<ObjectCorrespondence>& matches) const {
  for (const ObjectCorrespondence& m : matches) {
    if (m.observation < 0 || static_cast<size_t>(m.observation) >= observations.size())
      throw Error("refinementMatches: observation index " + std::to_string(m.observation) + " out of range (" +
                  std::to_string(observations.size()) + " observations)");
    if (m.object < 0 || static_cast<size_t>(m.object) >= map_.objects.size())
      throw Error("refinementMatches: object index " + std::to_string(m.object) + " out of range (" +
                  std::to_string(map_.objects.size()) + " map objects)");
  }
  const std::optional<GravityPrior> no_gravity;
  return ellipseMatches(matches, RefinementContext{observations, map_, K_, options_, no_gravity, PoseGate{}});
}

RelocalizationResult ObjectRelocalizer::relocalize(const std::vector<Observation>& observations) const {
  return relocalize(observations, {}, std::nullopt);
}

RelocalizationResult ObjectRelocalizer::relocalize(const std::vector<Observation>& observations,
                                                   const std::vector<Keypoint>& keypoints) const {
  return relocalize(observations, keypoints, std::nullopt);
}

RelocalizationResult ObjectRelocalizer::relocalize(const std::vector<Observation>& observations,
                                                   const std::vector<Keypoint>& keypoints,
                                                   const std::optional<GravityPrior>& gravity) const {
  return relocalize(observations, keypoints, gravity, std::nullopt);
}

RelocalizationResult ObjectRelocalizer::relocalize(const std::vector<Observation>& observations,
                                                   const std::vector<Keypoint>& keypoints,
                                                   const std::optional<GravityPrior>& gravity,
                                                   const std::optional<PoseRegion>& region) const {
  return relocalizeTimed(observations, keypoints, gravity, region, true);
}

RelocalizationResult ObjectRelocalizer::relocalizeUnpolished(const std::vector<Observation>& observations,
                                                             const std::optional<GravityPrior>& gravity) const {
  return relocalizeTimed(observations, {}, gravity, std::nullopt, false);
}

RelocalizationResult ObjectRelocalizer::relocalizeTimed(const std::vector<Observation>& observations,
                                                        const std::vector<Keypoint>& keypoints,
                                                        const std::optional<GravityPrior>& gravity,
                                                        const std::optional<PoseRegion>& region, bool polish) const {
  const auto start = std::chrono::steady_clock::now();  // the frame's clock: its time budget and time_ms
  const CanonicalFrame frame = inCanonicalOrder(observations);
  RelocalizationResult result =
      inGivenOrder(relocalizeInOrder(frame.observations, keypoints, gravity, region, start, polish), frame.order);
  result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

RelocalizationResult ObjectRelocalizer::relocalizeInOrder(const std::vector<Observation>& observations,
                                                          const std::vector<Keypoint>& keypoints,
                                                          const std::optional<GravityPrior>& gravity,
                                                          const std::optional<PoseRegion>& region,
                                                          std::chrono::steady_clock::time_point start,
                                                          bool polish) const {
  RelocalizationResult result;
  const auto finish = [&](RelocalizationStatus status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
    return result;
  };
  const std::string invalid = invalidInput(map_, K_, gravity, region, options_);
  if (!invalid.empty()) return finish(RelocalizationStatus::InvalidInput, invalid);

  // 1. Candidates: three usable observations for P3P, two for the two-object solver, one with gravity.
  const Candidates candidates =
      collectCandidates(observations, map_, options_.scoring, options_.search.max_candidate_pairs, &result.skipped);
  const int usable = candidates.num_usable;
  const bool few = options_.few_objects.enabled;
  const int needed = !few ? 3 : (gravity ? 1 : 2);
  if (usable < needed)
    return finish(RelocalizationStatus::NotEnoughObservations,
                  std::to_string(usable) + " usable observation(s) with a candidate object; " + std::to_string(needed) +
                      " needed" + (few && !gravity && usable == 1 ? " (or 1 with a gravity prior)" : ""));

  // A pose explains each usable observation at most fully: with fewer than the evidence the
  // acceptance test asks for, no pose could be reported, so none is searched for.
  if (options_.acceptance.enabled && usable < options_.acceptance.min_evidence) {
    char reason[200];
    std::snprintf(reason, sizeof reason,
                  "%d usable observation(s) cannot reach the evidence %.2f a pose needs (acceptance off gives the "
                  "pose for a host's own check)",
                  usable, options_.acceptance.min_evidence);
    return finish(RelocalizationStatus::NotEnoughObservations, reason);
  }

  // 2. Hypotheses into the pool: triplets, then pairs when the frame has few observations or
  // no triplet explains three.
  PoseScorer scorer(observations, candidates, map_, K_, options_.scoring);
  const PoseGate gate = frameGate(gravity, region, options_);
  HypothesisPool pool(options_.refinement.top_k, map_.unit_metres);
  const HypothesisEstimator estimator(observations, candidates, map_, K_, options_, gate, scorer, &pool);
  SearchOutcome search;
  const FrameBudget budget = frameBudget(options_.search, map_.objects.size(), usable, start);
  // Each further thread scores with its own scorer (scratch buffers).
  std::vector<PoseScorer> thread_scorers(static_cast<size_t>(options_.search.threads) - 1, scorer);
  std::vector<PoseScorer*> scorers = {&scorer};
  for (PoseScorer& s : thread_scorers) scorers.push_back(&s);
  if (usable >= 3) {
    const TripletSearch triplets{observations, map_, K_, options_, gate, budget};
    if (region)  // only pairs that can give a pose in the region
      triplets.run(candidatesWithinRegion(candidates, observations, map_, K_, *region), scorers, &pool, &search);
    else
      triplets.run(candidates, scorers, &pool, &search);
  }
  if (few && (usable <= options_.few_objects.max_observations || search.best_inliers < 3))
    searchFewObjects(estimator, candidates, options_, gravity, region, budget, &pool, &search);
  if (region && gate.admits(region->pose)) offerRegionPose(estimator, region->pose, &pool, &search);
  result.hypotheses = search.hypotheses;
  result.few_object_hypotheses = search.few_object_hypotheses;
  result.iterations = search.iterations;
  result.budget_exhausted = search.budget_exhausted;
  if (!search.found)
    return finish(RelocalizationStatus::NoConsistentHypothesis, "no hypothesis gave a pose with its objects in view");

  // 3. Refinement of the pooled hypotheses, then with the keypoints.
  const RefinementContext context{observations, map_, K_, options_, gravity, gate};
  // Past the time budget only the best hypothesis is refined: the bound is the budget plus one refinement.
  ChosenPose chosen =
      refineHypotheses(pool, search.best, scorers, context, budget.timeUp() ? 1 : pool.entries().size());
  if (polish) chosen = polishPose(std::move(chosen), scorer, context);
  chosen = refineWithPoints(std::move(chosen), pointMatches(keypoints, map_), scorer, context);

  // 4. The result.
  result.pose = chosen.pose;
  result.cost = chosen.cost;
  result.refined = chosen.refined;
  result.margin = chosen.margin;
  result.alternatives = chosen.alternatives;
  if (!result.alternatives.empty()) result.rival = result.alternatives.front().pose;
  reportMatches(chosen.matches, usable, options_.acceptance, &result);
  const int min_inliers = usable == 1 ? 1 : options_.scoring.min_inliers;  // one observation needs gravity (above)
  if (static_cast<int>(chosen.matches.size()) < min_inliers)
    return finish(RelocalizationStatus::NoConsistentHypothesis,
                  "best pose explains " + std::to_string(chosen.matches.size()) + " observation(s); " +
                      std::to_string(min_inliers) + " needed");
  if (options_.acceptance.enabled && result.evidence < options_.acceptance.min_evidence) {
    char reason[160];
    std::snprintf(reason, sizeof reason, "evidence %.2f below %.2f: %zu of %d usable observations explained",
                  result.evidence, options_.acceptance.min_evidence, chosen.matches.size(), usable);
    return finish(RelocalizationStatus::LowEvidence, reason);
  }
  if (options_.acceptance.enabled && result.margin < options_.acceptance.min_margin) {
    char reason[160];
    std::snprintf(reason, sizeof reason,
                  "margin %.2f below %.2f: another pose explains the observations almost as well", result.margin,
                  options_.acceptance.min_margin);
    return finish(RelocalizationStatus::LowEvidence, reason);
  }
  return finish(RelocalizationStatus::Success, "");
}

}  // namespace ellreloc
