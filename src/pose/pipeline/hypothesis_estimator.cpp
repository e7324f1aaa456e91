#include "hypothesis_estimator.hpp"

#include <array>
#include <cmath>
#include <limits>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/p3p.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/pose/few_object_poses.hpp"

namespace ellreloc::pipeline {

namespace {

EllipseMatch ellipseMatchOf(const CandidatePair& pair, const std::vector<Observation>& observations,
                            const ObjectMap& map) {
  return {observations[static_cast<size_t>(pair.observation)].ellipse,
          map.objects[static_cast<size_t>(pair.object)].ellipsoid};
}

}  // namespace

HypothesisSampler frameSampler(const Candidates& candidates, const SearchOptions& search) {
  if (search.sampler != HypothesisSampler::Auto) return search.sampler;
  // What enumerating costs is the triplets of distinct observations, not all n choose 3
  // triplets of pairs (most repeat an observation and are dropped at once).
  return usableTriplets(candidates) <= static_cast<double>(search.max_exhaustive_triplets)
             ? HypothesisSampler::Exhaustive
             : HypothesisSampler::Prosac;
}

EllipseMatch refinerMatch(const Observation& o, const Ellipsoid& e, const RefinementStageOptions& options) {
  const bool regular_fit = o.source == EllipseSource::Mask && o.regular.value_or(false);
  return {o.ellipse, e, regular_fit ? options.regular_mask_sigma : 1.0};
}

bool HypothesisEstimator::accept(const Pose& pose, const int* pair_indices, int count, bool check_overlap,
                                 KnownProjections* own) const {
  if (!gate_.admits(pose)) return false;
  own->count = 0;
  const std::optional<Eigen::Matrix<double, 3, 4>> P = scorer_.projectionAt(pose);
  if (!P) return false;
  const double min_overlap = options_.scoring.min_overlap;
  // Three in five P3P poses fail here, nearly all on an overlap bound: every own pair's bound
  // is checked as soon as it is projected, before any exact overlap.
  for (int k = 0; k < count; ++k) {
    const CandidatePair& c = pairs_[static_cast<size_t>(pair_indices[k])];
    const Projection p = scorer_.projectObject(c.object, *P, pose);
    if (!p.ok()) return false;
    if (check_overlap &&
        !scorer_.overlapMayReach(static_cast<size_t>(c.observation), p.ellipse, kRankingIoUVertices, min_overlap))
      return false;
    own->objects[k] = c.object;
    own->ellipses[k] = p.ellipse;
    own->count = k + 1;
  }
  for (int k = 0; k < count && check_overlap; ++k) {
    const Observation& o = observations_[pairs_[pair_indices[k]].observation];
    if (!scorer_.overlapCertainlyReaches(o, own->ellipses[k], kRankingIoUVertices, min_overlap) &&
        scorer_.overlap(o, own->ellipses[k], kRankingIoUVertices) < min_overlap)
      return false;
  }
  return true;
}

int HypothesisEstimator::generate(const int* s, Model* models) const {
  const CandidatePair &a = pairs_[s[0]], &b = pairs_[s[1]], &c = pairs_[s[2]];
  if (a.observation == b.observation || a.observation == c.observation || b.observation == c.observation ||
      a.object == b.object || a.object == c.object || b.object == c.object)
    return 0;
  std::array<Eigen::Vector3d, 3> bearings, centres;
  for (int k = 0; k < 3; ++k) {
    const CandidatePair& pair = pairs_[s[k]];
    bearings[k] = K_.bearing(observations_[pair.observation].ellipse.center());
    centres[k] = map_.objects[pair.object].ellipsoid.center();
  }
  std::array<Pose, 4> poses;
  const int n = p3p(bearings, centres, &poses);
  int count = 0;
  for (int i = 0; i < n; ++i) {
    Model m{poses[i], {}};
    // The gate first: a few operations, where the correction costs a P3P and three projections.
    // A correction moves a pose by millimetres to centimetres (accept() gates the corrected
    // pose again); the rare one that jumps to another P3P branch is no correction of this pose.
    if (!gate_.admits(m.pose)) continue;
    // Two in five P3P poses put an own object where its image is certainly too large or too
    // small for its observation: area bounds show it in a few operations, before the correction
    // and the projections. A correction moves a pose far less than the factor 1 / min_overlap in
    // area that this tolerates; the few poses it would carry past it jump to another P3P root.
    if (options_.search.check_sample_overlap && !ownSizesMayFit(m.pose, s)) continue;
    if (sampled_ && options_.search.correct_centres && options_.search.uncorrected_when_closer) {
      if (correctedOrNot(s, &m)) models[count++] = m;
      continue;
    }
    if (options_.search.correct_centres && !correctCentres(s, &m.pose)) continue;
    if (accept(m.pose, s, 3, options_.search.check_sample_overlap, &m.own)) models[count++] = m;
  }
  return count;
}

bool HypothesisEstimator::correctedOrNot(const int* s, Model* model) const {
  const bool check = options_.search.check_sample_overlap;
  Model corrected = *model;
  const bool corrected_ok = correctCentres(s, &corrected.pose) && accept(corrected.pose, s, 3, check, &corrected.own);
  const bool plain_ok = accept(model->pose, s, 3, check, &model->own);
  if (corrected_ok && (!plain_ok || ownFit(s, corrected.own) <= ownFit(s, model->own))) *model = corrected;
  return corrected_ok || plain_ok;
}

double HypothesisEstimator::ownFit(const int* s, const KnownProjections& own) const {
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    const Ellipse& observed = observations_[static_cast<size_t>(pairs_[s[k]].observation)].ellipse;
    sum += wasserstein2Squared(observed, own.ellipses[k]) / observed.axes().prod();
  }
  return sum;
}

bool HypothesisEstimator::ownSizesMayFit(const Pose& pose, const int* s) const {
  for (int k = 0; k < 3; ++k) {
    const CandidatePair& c = pairs_[s[k]];
    if (!scorer_.sizeMayReach(observations_[c.observation], c.object, pose, options_.scoring.min_overlap)) return false;
  }
  return true;
}

/// The centre of a projected ellipsoid's image is not the image of its centre: remove that
/// offset (measured at the current pose) from the observed centres and solve P3P again.
bool HypothesisEstimator::correctCentres(const int* s, Pose* pose) const {
  const std::optional<Eigen::Matrix<double, 3, 4>> P = scorer_.projectionAt(*pose);
  if (!P) return false;
  std::array<Eigen::Vector3d, 3> bearings, centres;
  for (int k = 0; k < 3; ++k) {
    const Ellipsoid& e = map_.objects[pairs_[s[k]].object].ellipsoid;
    const std::optional<Eigen::Vector2d> image_centre = scorer_.projectedCentre(pairs_[s[k]].object, *P);
    if (!image_centre) return false;
    const Eigen::Vector2d offset = *image_centre - K_.project(pose->transform(e.center()));
    bearings[k] = K_.bearing(observations_[pairs_[s[k]].observation].ellipse.center() - offset);
    centres[k] = e.center();
  }
  std::array<Pose, 4> poses;
  const int n = p3p(bearings, centres, &poses);
  // The root nearest the uncorrected pose: a radian of turn weighs as a metre of shift.
  const Pose uncorrected = *pose;
  double best = 1e9;
  for (int i = 0; i < n; ++i) {
    const double d = rotationErrorDeg(poses[i].rotation(), uncorrected.rotation()) * M_PI / 180.0 +
                     (poses[i].center() - uncorrected.center()).norm() * map_.unit_metres;
    if (d < best) best = d, *pose = poses[i];
  }
  return n > 0;
}

double HypothesisEstimator::score(const Model& model, int* num_inliers) const {
  thread_local std::vector<ObjectCorrespondence> matches;
  const double give_up_at = pool_ ? pool_->admissionCost() : std::numeric_limits<double>::infinity();
  const double cost = scorer_.cost(model.pose, kRankingIoUVertices, &matches, &model.own, give_up_at);
  *num_inliers = static_cast<int>(matches.size());
  return cost;
}

double HypothesisEstimator::refineIfLoose(Model* model, double cost, int* num_inliers, double admission) const {
  // Few hypotheses explain every observation (tens in a frame of thousands), so refining them
  // costs little; one that is loose is most often a right triplet's pose centimetres off.
  const SearchOptions& search = options_.search;
  if (!search.refine_explained || num_usable_ < kMinExplainedObservations || *num_inliers < num_usable_ ||
      !(cost > explainedCost(search, num_usable_)) || !(cost < admission))
    return cost;
  thread_local std::vector<ObjectCorrespondence> matches;
  scorer_.cost(model->pose, kRankingIoUVertices, &matches, &model->own);  // its matches, as scored
  std::vector<EllipseMatch> pairs;
  pairs.reserve(matches.size());
  for (const ObjectCorrespondence& m : matches)
    pairs.push_back(refinerMatch(observations_[static_cast<size_t>(m.observation)],
                                 map_.objects[static_cast<size_t>(m.object)].ellipsoid, options_.refinement));
  const RefinementResult r = refinePose(K_, model->pose, pairs, {}, options_.refinement.refiner);
  if (r.fell_back || !gate_.admits(r.pose)) return cost;
  thread_local std::vector<ObjectCorrespondence> rematched;
  const double refined_cost = scorer_.cost(r.pose, kRankingIoUVertices, &rematched, nullptr, admission);
  if (!(refined_cost < cost)) return cost;
  model->pose = r.pose;
  model->own.count = 0;  // its projections were the unrefined pose's
  *num_inliers = static_cast<int>(rematched.size());
  return refined_cost;
}

void HypothesisEstimator::fromSolver(const std::vector<ScoredPose>& poses, const int* pair_indices, int count,
                                     std::vector<Model>* out) const {
  for (const ScoredPose& p : poses) {
    Model m{p.pose, {}};
    // The pairs the pose came from must match at it.
    if (accept(m.pose, pair_indices, count, /*check_overlap=*/true, &m.own)) out->push_back(m);
  }
}

void HypothesisEstimator::fromTwoPairs(int a, int b, const std::optional<GravityPrior>& gravity,
                                       const std::optional<PoseRegion>& region, std::vector<Model>* out) const {
  const int own[2] = {a, b};
  fromSolver(posesFromTwoObjects(K_, ellipseMatchOf(pairs_[a], observations_, map_),
                                 ellipseMatchOf(pairs_[b], observations_, map_), gravity, options_.few_objects.solver,
                                 options_.envelope, region),
             own, 2, out);
}

void HypothesisEstimator::fromOnePair(int a, const GravityPrior& gravity, std::vector<Model>* out) const {
  fromSolver(
      posesFromOneObject(K_, ellipseMatchOf(pairs_[a], observations_, map_), gravity, options_.few_objects.solver), &a,
      1, out);
}

}  // namespace ellreloc::pipeline
