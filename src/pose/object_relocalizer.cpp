#include "ellreloc/pose/object_relocalizer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/core/p3p.hpp"

namespace ellreloc {

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
  }
  return "unknown";
}

namespace {

/// Vertices of the polygon used by ellipseIoU while scoring hypotheses: IoU error ~1e-2,
/// ample to rank poses (fr2_desk and simulated results identical to 48), 3x faster than 128.
constexpr int kScoringIoUVertices = 32;

struct CandidatePair {
  int obs;
  int obj;
  double quality;  // detection score x apparent object size: PROSAC order
};

struct Match {
  int obs;
  int obj;
  double overlap;
  double credit;  // overlap x label weight: what the match is worth in the cost
};

/// Scores poses: projects the relevant map objects and matches them to the observations.
/// Holds per-call scratch buffers, so one Scorer must not be shared between threads.
class Scorer {
 public:
  Scorer(const std::vector<Observation>& obs, const std::vector<char>& obs_valid,
         const std::vector<std::vector<int>>& candidates_of_obs, const ObjectMap& map, const Intrinsics& K,
         const RelocalizerOptions& opt)
      : obs_(obs), obs_valid_(obs_valid), cands_(candidates_of_obs), map_(map), K_(K), opt_(opt) {
    std::vector<char> relevant(map.objects.size(), 0);
    for (const auto& c : cands_)
      for (int j : c) relevant[j] = 1;
    for (size_t j = 0; j < relevant.size(); ++j)
      if (relevant[j]) relevant_.push_back(static_cast<int>(j));
    // A match to an object that carried the observed label in only a minority of its
    // detections is worth that share of a match (full at a majority, share >= 0.5).
    label_weight_.resize(cands_.size());
    for (size_t i = 0; i < cands_.size(); ++i)
      for (int j : cands_[i]) {
        const MapObject& m = map.objects[static_cast<size_t>(j)];
        const bool weigh = opt.weigh_minority_labels && m.category != obs[i].category;
        label_weight_[i].push_back(weigh ? std::min(1.0, m.categoryShare(obs[i].category) / 0.5) : 1.0);
      }
    proj_.resize(map.objects.size());
    proj_ok_.resize(map.objects.size(), 0);
    obs_used_.resize(obs.size());
    obj_used_.resize(map.objects.size());
    matches_.reserve(64);
    for (size_t i = 0; i < obs.size(); ++i) num_valid_ += obs_valid[i] ? 1 : 0;
  }

  /// Truncated cost of a pose; fills the one-to-one matches when asked.
  double cost(const Pose& pose, int vertices, std::vector<Match>* out = nullptr) const {
    for (int j : relevant_) {
      const Projection p = project(map_.objects[j].ellipsoid, K_, pose);
      proj_ok_[j] = p.ok();
      if (p.ok()) proj_[j] = p.ellipse;
    }
    matches_.clear();
    for (size_t i = 0; i < obs_.size(); ++i) {
      if (!obs_valid_[i]) continue;
      const Observation& o = obs_[i];
      for (size_t k = 0; k < cands_[i].size(); ++k) {
        const int j = cands_[i][k];
        if (!proj_ok_[j]) continue;
        const Box pb = proj_[j].boundingBox();
        if (pb.x2 <= o.box.x1 || o.box.x2 <= pb.x1 || pb.y2 <= o.box.y1 || o.box.y2 <= pb.y1) continue;
        const double overlap =
            opt_.overlap == OverlapMeasure::BoxIoU ? boxIoU(o.box, pb) : ellipseIoU(o.ellipse, proj_[j], vertices);
        if (overlap >= opt_.min_overlap)
          matches_.push_back({static_cast<int>(i), j, overlap, overlap * label_weight_[i][k]});
      }
    }
    std::sort(matches_.begin(), matches_.end(), [](const Match& a, const Match& b) {
      return a.credit != b.credit ? a.credit > b.credit : (a.obs != b.obs ? a.obs < b.obs : a.obj < b.obj);
    });
    std::fill(obs_used_.begin(), obs_used_.end(), 0);
    std::fill(obj_used_.begin(), obj_used_.end(), 0);
    const double miss = opt_.unmatched_cost;
    double total = miss * num_valid_;
    if (out) out->clear();
    for (const Match& m : matches_) {
      if (obs_used_[m.obs] || obj_used_[m.obj]) continue;
      obs_used_[m.obs] = obj_used_[m.obj] = 1;
      total += (1.0 - m.credit) - miss;
      if (out) out->push_back(m);
    }
    return total;
  }

  int numValid() const { return num_valid_; }

 private:
  const std::vector<Observation>& obs_;
  const std::vector<char>& obs_valid_;
  const std::vector<std::vector<int>>& cands_;
  const ObjectMap& map_;
  const Intrinsics& K_;
  const RelocalizerOptions& opt_;
  std::vector<int> relevant_;
  std::vector<std::vector<double>> label_weight_;  // per observation, per candidate
  int num_valid_ = 0;
  mutable std::vector<Ellipse> proj_;
  mutable std::vector<char> proj_ok_;
  mutable std::vector<Match> matches_;
  mutable std::vector<char> obs_used_, obj_used_;
};

struct Hypothesis {
  double cost;
  Pose pose;
};

/// RANSAC estimator over candidate pairs (see ransac.hpp for the concept).
struct PairEstimator {
  using Model = Pose;
  static constexpr int kSampleSize = 3;
  static constexpr int kMaxModels = 4;

  const std::vector<CandidatePair>& pairs;
  const std::vector<Observation>& obs;
  const ObjectMap& map;
  const Intrinsics& K;
  const RelocalizerOptions& opt;
  const Scorer& scorer;
  const GravityPrior* gravity;          // drop poses that tilt the camera wrongly, when set
  mutable std::vector<Hypothesis> top;  // best distinct hypotheses, ascending cost

  bool agreesWithGravity(const Pose& pose) const {
    return !gravity || gravity->errorDeg(pose) <= std::max(opt.gravity_gate_deg, 5.0 * gravity->sigma_deg);
  }

  size_t numData() const { return pairs.size(); }

  double overlap(const Observation& o, const Ellipse& projected) const {
    return opt.overlap == OverlapMeasure::BoxIoU ? boxIoU(o.box, projected.boundingBox())
                                                 : ellipseIoU(o.ellipse, projected, kScoringIoUVertices);
  }

  int generate(const int* s, Model* models) const {
    const CandidatePair& a = pairs[s[0]];
    const CandidatePair& b = pairs[s[1]];
    const CandidatePair& c = pairs[s[2]];
    if (a.obs == b.obs || a.obs == c.obs || b.obs == c.obs || a.obj == b.obj || a.obj == c.obj || b.obj == c.obj)
      return 0;
    const int ob[3] = {a.obs, b.obs, c.obs};
    const int oj[3] = {a.obj, b.obj, c.obj};
    std::array<Eigen::Vector3d, 3> bearings, centres;
    for (int k = 0; k < 3; ++k) {
      bearings[k] = K.bearing(obs[ob[k]].ellipse.center());
      centres[k] = map.objects[oj[k]].ellipsoid.center();
    }
    std::array<Pose, 4> poses;
    const int n = p3p(bearings, centres, &poses);
    int count = 0;
    for (int i = 0; i < n; ++i) {
      Pose pose = poses[i];
      if (opt.correct_centres && !correctCentres(ob, oj, &pose)) continue;
      if (!agreesWithGravity(pose)) continue;
      bool visible = true;
      for (int k = 0; k < 3 && visible; ++k) {
        const Projection p = project(map.objects[oj[k]].ellipsoid, K, pose);
        visible = p.ok() && (!opt.check_sample_overlap || overlap(obs[ob[k]], p.ellipse) >= opt.min_overlap);
      }
      if (visible) models[count++] = pose;
    }
    return count;
  }

  /// The centre of a projected ellipsoid's image is not the image of its centre: remove that
  /// offset (measured at the current pose) from the observed centres and solve P3P again.
  bool correctCentres(const int* ob, const int* oj, Pose* pose) const {
    std::array<Eigen::Vector3d, 3> bearings, centres;
    for (int k = 0; k < 3; ++k) {
      const Ellipsoid& e = map.objects[oj[k]].ellipsoid;
      const Projection p = project(e, K, *pose);
      if (!p) return false;
      const Eigen::Vector2d offset = p.ellipse.center() - K.project(pose->transform(e.center()));
      bearings[k] = K.bearing(obs[ob[k]].ellipse.center() - offset);
      centres[k] = e.center();
    }
    std::array<Pose, 4> poses;
    const int n = p3p(bearings, centres, &poses);
    double best = 1e9;
    for (int i = 0; i < n; ++i) {
      const double d = rotationErrorDeg(poses[i].rotation(), pose->rotation()) * M_PI / 180.0 +
                       (poses[i].center() - pose->center()).norm();
      if (d < best) best = d, *pose = poses[i];
    }
    return n > 0;
  }

  double score(const Model& pose, int* inliers) const {
    thread_local std::vector<Match> matches;
    const double c = scorer.cost(pose, kScoringIoUVertices, &matches);
    *inliers = static_cast<int>(matches.size());
    remember(c, pose);
    return c;
  }

  void refine(Model*) const {}

  /// Keeps the refine_top_k best hypotheses, one per pose neighbourhood.
  void remember(double cost, const Pose& pose) const {
    const size_t k = static_cast<size_t>(std::max(1, opt.refine_top_k));
    if (top.size() == k && cost >= top.back().cost) return;
    for (Hypothesis& h : top) {
      if ((h.pose.center() - pose.center()).norm() < 0.05 &&
          rotationErrorDeg(h.pose.rotation(), pose.rotation()) < 3.0) {
        if (cost < h.cost) h = {cost, pose};
        std::sort(top.begin(), top.end(), [](const Hypothesis& x, const Hypothesis& y) { return x.cost < y.cost; });
        return;
      }
    }
    top.push_back({cost, pose});
    std::sort(top.begin(), top.end(), [](const Hypothesis& x, const Hypothesis& y) { return x.cost < y.cost; });
    if (top.size() > k) top.pop_back();
  }
};

/// Usable observations and their candidate objects (same category, or a share of the
/// object's label histogram).
struct Candidates {
  std::vector<char> valid;                       // per observation
  std::vector<std::vector<int>> of_observation;  // candidate objects of each observation
  std::vector<CandidatePair> pairs;              // best (PROSAC) first
  int usable = 0;
};

Candidates collectCandidates(const std::vector<Observation>& observations, const ObjectMap& map,
                             const RelocalizerOptions& options, std::vector<std::pair<int, std::string>>* skipped) {
  Candidates c;
  c.valid.assign(observations.size(), 0);
  c.of_observation.resize(observations.size());
  for (size_t i = 0; i < observations.size(); ++i) {
    const Observation& o = observations[i];
    if (!o.ellipse.isValid() || !o.box.isValid() || !std::isfinite(o.score)) {
      skipped->emplace_back(static_cast<int>(i), "invalid ellipse, box or score (NaN, infinite or empty)");
      continue;
    }
    for (size_t j = 0; j < map.objects.size(); ++j) {
      const MapObject& m = map.objects[j];
      const double share =
          m.category == o.category ? std::max(m.categoryShare(o.category), 0.5) : m.categoryShare(o.category);
      if (!m.ellipsoid.isValid() || !(share >= std::min(options.min_category_share, 0.5) &&
                                      (m.category == o.category || share >= options.min_category_share)))
        continue;
      c.of_observation[i].push_back(static_cast<int>(j));
      // Likelier labels, surer detections and larger objects first: PROSAC order.
      c.pairs.push_back({static_cast<int>(i), static_cast<int>(j), share * o.score * std::cbrt(m.ellipsoid.volume())});
    }
    if (c.of_observation[i].empty()) {
      skipped->emplace_back(static_cast<int>(i), "no map object of category " + std::to_string(o.category));
      continue;
    }
    c.valid[i] = 1;
    ++c.usable;
  }
  std::stable_sort(c.pairs.begin(), c.pairs.end(),
                   [](const CandidatePair& a, const CandidatePair& b) { return a.quality > b.quality; });
  return c;
}

/// The matches of a pose as the result's correspondences, and their mean overlap.
void reportMatches(const std::vector<Match>& matches, RelocalizationResult* result) {
  double sum = 0.0;
  for (const Match& m : matches) {
    result->inliers.push_back({m.obs, m.obj, m.overlap});
    sum += m.overlap;
  }
  result->mean_overlap = matches.empty() ? 0.0 : sum / matches.size();
}

/// The P3P loop: RANSAC over triplets of candidate pairs with the sampler and budgets of the
/// options. Fills the statistics of `result` and the best pose's match count; false when no
/// triplet gave a pose.
bool searchTriplets(const PairEstimator& estimator, const RelocalizerOptions& options, size_t num_objects, int usable,
                    Pose* best, int* best_inliers, RelocalizationResult* result) {
  RansacOptions ropt = options.ransac;
  // Scoring a hypothesis costs up to (map objects) x (usable observations) overlaps: a large
  // map with many observations gets fewer hypotheses, so that the worst case stays bounded.
  if (options.max_overlap_evaluations > 0) {
    const double per_hypothesis = static_cast<double>(num_objects) * static_cast<double>(usable);
    const long affordable = static_cast<long>(static_cast<double>(options.max_overlap_evaluations) / per_hypothesis);
    ropt.max_hypotheses = std::min(ropt.max_hypotheses, std::max(affordable, options.min_hypotheses_budget));
  }
  const int n = static_cast<int>(estimator.pairs.size());
  HypothesisSampler sampler = options.sampler;
  if (sampler == HypothesisSampler::Auto) {
    const double triplets = static_cast<double>(n) * (n - 1) * (n - 2) / 6.0;
    sampler = triplets <= options.max_exhaustive_triplets ? HypothesisSampler::Exhaustive : HypothesisSampler::Prosac;
  }
  if (sampler == HypothesisSampler::Exhaustive) {
    // Small enough to try everything: the budgets still bound it.
    ropt.min_iterations = std::max(ropt.min_iterations, std::numeric_limits<int>::max() / 2);
    ropt.max_iterations = std::max(ropt.max_iterations, std::numeric_limits<int>::max() / 2);
  }
  RansacStats stats;
  bool found = false;
  switch (sampler) {
    case HypothesisSampler::Auto:  // resolved above
    case HypothesisSampler::Exhaustive: {
      ExhaustiveSampler s(n, 3);
      found = ransac(estimator, s, ropt, best, &stats);
      break;
    }
    case HypothesisSampler::Uniform: {
      UniformSampler s(n, 3, ropt.seed);
      found = ransac(estimator, s, ropt, best, &stats);
      break;
    }
    case HypothesisSampler::Prosac: {
      // Reach uniform sampling over all pairs within ~1000 samples: the MSAC stopping rule
      // assumes samples from all the data, and a wrong early model must not end the search
      // while good pairs of lower quality are still out of reach.
      ProsacSampler s(n, 3, ropt.seed, 1000);
      found = ransac(estimator, s, ropt, best, &stats);
      break;
    }
  }
  result->hypotheses = stats.hypotheses;
  result->iterations = stats.iterations;
  result->budget_exhausted = stats.budget_exhausted;
  *best_inliers = stats.num_inliers;
  return found;
}

}  // namespace

ObjectRelocalizer::ObjectRelocalizer(ObjectMap map, const Intrinsics& K, RelocalizerOptions options)
    : map_(std::move(map)), K_(K), options_(std::move(options)) {}

RelocalizationResult ObjectRelocalizer::scorePose(const std::vector<Observation>& observations,
                                                  const Pose& pose) const {
  RelocalizationResult result;
  result.pose = pose;
  if (!K_.isValid() || !pose.isValid()) {
    result.status = RelocalizationStatus::InvalidInput;
    result.reason = !K_.isValid() ? "invalid intrinsics" : "invalid pose";
    return result;
  }
  const Candidates cands = collectCandidates(observations, map_, options_, &result.skipped);
  const Scorer scorer(observations, cands.valid, cands.of_observation, map_, K_, options_);
  std::vector<Match> matches;
  result.cost = scorer.cost(pose, 128, &matches);
  reportMatches(matches, &result);
  const bool enough = static_cast<int>(matches.size()) >= std::min(options_.min_inliers, std::max(cands.usable, 1));
  result.status = enough ? RelocalizationStatus::Success : RelocalizationStatus::NoConsistentHypothesis;
  if (!enough) result.reason = "the pose explains " + std::to_string(matches.size()) + " observation(s)";
  return result;
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
  std::vector<PointMatch> points;
  for (const Keypoint& k : keypoints)
    if (k.point_index >= 0 && static_cast<size_t>(k.point_index) < map_.points.size() && k.uv.allFinite() &&
        map_.points[static_cast<size_t>(k.point_index)].allFinite())
      points.push_back({k.uv, map_.points[static_cast<size_t>(k.point_index)]});
  const auto start = std::chrono::steady_clock::now();
  RelocalizationResult result;
  const auto finish = [&](RelocalizationStatus status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
    result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  if (!K_.isValid()) return finish(RelocalizationStatus::InvalidInput, "invalid intrinsics");
  if (gravity && !gravity->isValid())
    return finish(RelocalizationStatus::InvalidInput,
                  "invalid gravity prior (zero or non-finite direction, or sigma not positive)");

  const Candidates cands = collectCandidates(observations, map_, options_, &result.skipped);
  const std::vector<CandidatePair>& pairs = cands.pairs;
  const int usable = cands.usable;
  // Three observations for P3P; two for the two-object solver; one with gravity.
  const bool few = options_.few_object_solvers;
  const int needed = !few ? 3 : (gravity ? 1 : 2);
  if (usable < needed)
    return finish(RelocalizationStatus::NotEnoughObservations,
                  std::to_string(usable) + " usable observation(s) with a candidate object; " + std::to_string(needed) +
                      " needed" + (few && !gravity && usable == 1 ? " (or 1 with a gravity prior)" : ""));

  const Scorer scorer(observations, cands.valid, cands.of_observation, map_, K_, options_);
  const PairEstimator estimator{pairs, observations, map_, K_, options_, scorer, gravity ? &*gravity : nullptr, {}};
  const auto matchOf = [&](const auto& pair) {  // a CandidatePair or a Match
    return EllipseMatch{observations[pair.obs].ellipse, map_.objects[pair.obj].ellipsoid};
  };
  const auto matchesOf = [&](const std::vector<Match>& matches) {
    std::vector<EllipseMatch> em;
    for (const Match& m : matches) em.push_back(matchOf(m));
    return em;
  };
  // The prior joins a refinement where the objects leave the tilt weakly constrained.
  const auto refinementGravity = [&](size_t matched) {
    return matched < 3 || options_.gravity_in_every_refinement ? gravity : std::nullopt;
  };
  Pose best;
  bool found = false;
  int best_inliers = 0;
  if (usable >= 3)
    found = searchTriplets(estimator, options_, map_.objects.size(), usable, &best, &best_inliers, &result);

  // Few observations, or no triplet explains three: poses from pairs, or from one object and
  // gravity. They compete with the triplets' poses in the same score.
  if (few && (usable <= options_.pair_search_max_observations || best_inliers < 3)) {
    const long before = result.hypotheses;
    const auto consider = [&](const std::vector<ScoredPose>& poses, const std::vector<int>& own) {
      for (const ScoredPose& p : poses) {
        if (!estimator.agreesWithGravity(p.pose)) continue;
        bool visible = true;  // the pairs the pose came from must match at it
        for (size_t k = 0; k < own.size() && visible; ++k) {
          const CandidatePair& c = pairs[static_cast<size_t>(own[k])];
          const Projection proj = project(map_.objects[c.obj].ellipsoid, K_, p.pose);
          visible = proj.ok() && estimator.overlap(observations[c.obs], proj.ellipse) >= options_.min_overlap;
        }
        if (!visible) continue;
        ++result.hypotheses;
        int inliers = 0;
        estimator.score(p.pose, &inliers);
        found = true;
      }
    };
    long tried = 0;
    for (size_t i = 0; i < pairs.size() && tried < options_.max_pair_hypotheses; ++i)
      for (size_t j = i + 1; j < pairs.size() && tried < options_.max_pair_hypotheses; ++j) {
        if (pairs[i].obs == pairs[j].obs || pairs[i].obj == pairs[j].obj) continue;
        ++tried;
        consider(posesFromTwoObjects(K_, matchOf(pairs[i]), matchOf(pairs[j]), gravity, options_.few_object),
                 {static_cast<int>(i), static_cast<int>(j)});
      }
    if (gravity && usable == 1)
      for (size_t i = 0; i < pairs.size() && tried < options_.max_pair_hypotheses; ++i, ++tried)
        consider(posesFromOneObject(K_, matchOf(pairs[i]), *gravity, options_.few_object), {static_cast<int>(i)});
    result.few_object_hypotheses = result.hypotheses - before;
    if (!estimator.top.empty()) best = estimator.top.front().pose;
  }
  if (!found)
    return finish(RelocalizationStatus::NoConsistentHypothesis, "no hypothesis gave a pose with its objects in view");

  // Refine the best distinct hypotheses on all their matches; keep what scores best.
  std::vector<Match> matches;
  double best_cost = scorer.cost(best, 128, &matches);
  for (const Hypothesis& h : estimator.top) {
    if (h.cost > estimator.top.front().cost + options_.refine_cost_margin) break;  // ascending costs
    Pose candidate = h.pose;
    bool refined = false;
    double cost = scorer.cost(candidate, 128, &matches);
    // Refine on the matches, match again at the refined pose, and repeat while that explains
    // the observations better: a refined pose often brings more objects into overlap.
    for (int round = 0; round < options_.refine_rounds && options_.refine; ++round) {
      if (static_cast<int>(matches.size()) < (gravity ? 1 : 2)) break;
      const RefinementResult r =
          refinePose(K_, candidate, matchesOf(matches), {}, options_.refiner, refinementGravity(matches.size()));
      if (r.fell_back || !estimator.agreesWithGravity(r.pose)) break;
      std::vector<Match> rematched;
      const double refined_cost = scorer.cost(r.pose, 128, &rematched);
      if (refined_cost > cost) break;
      const bool more = rematched.size() > matches.size();
      candidate = r.pose;
      cost = refined_cost;
      refined = true;
      matches = std::move(rematched);
      if (!more) break;
    }
    if (cost < best_cost || (refined && cost <= best_cost)) {
      best_cost = cost;
      best = candidate;
      result.refined = refined;
    }
  }
  double final_cost = scorer.cost(best, 128, &matches);
  // Points pull the chosen pose towards what the overlap measure cannot see; the result is
  // kept when it still explains as many observations.
  if (!points.empty() && options_.refine && !matches.empty()) {
    const RefinementResult r =
        refinePose(K_, best, matchesOf(matches), points, options_.refiner, refinementGravity(matches.size()));
    std::vector<Match> with_points;
    const double cost_with_points = r.fell_back ? 0.0 : scorer.cost(r.pose, 128, &with_points);
    if (!r.fell_back && with_points.size() >= matches.size() && estimator.agreesWithGravity(r.pose)) {
      best = r.pose;
      final_cost = cost_with_points;
      matches = std::move(with_points);
      result.refined = true;
    }
  }
  result.pose = best;
  result.cost = final_cost;
  reportMatches(matches, &result);
  const int min_inliers = usable == 1 ? 1 : options_.min_inliers;  // a single observation needs gravity (above)
  if (static_cast<int>(matches.size()) < min_inliers)
    return finish(RelocalizationStatus::NoConsistentHypothesis, "best pose explains " + std::to_string(matches.size()) +
                                                                    " observation(s); " + std::to_string(min_inliers) +
                                                                    " needed");
  return finish(RelocalizationStatus::Success, "");
}

}  // namespace ellreloc
