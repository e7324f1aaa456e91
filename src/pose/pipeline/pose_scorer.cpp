#include "pose_scorer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/projection.hpp"

namespace ellreloc::pipeline {

PoseScorer::PoseScorer(const std::vector<Observation>& observations, const Candidates& candidates, const ObjectMap& map,
                       const Intrinsics& K, const ScoringOptions& options)
    : observations_(observations), candidates_(candidates), K_(K), options_(options) {
  const auto& cands = candidates.of_observation;
  std::vector<char> relevant(map.objects.size(), 0);
  for (const auto& c : cands)
    for (int j : c) relevant[static_cast<size_t>(j)] = 1;
  candidate_area_.assign(map.objects.size(), Box(INFINITY, INFINITY, -INFINITY, -INFINITY));
  candidate_observations_.resize(map.objects.size());
  for (size_t i = 0; i < cands.size(); ++i)
    for (int j : cands[i]) {
      if (!candidates.usable[i]) continue;  // never scored
      Box& a = candidate_area_[static_cast<size_t>(j)];
      const Box& b = observations[i].box;
      a = Box(std::min(a.x1, b.x1), std::min(a.y1, b.y1), std::max(a.x2, b.x2), std::max(a.y2, b.y2));
      candidate_observations_[static_cast<size_t>(j)].push_back(static_cast<int>(i));
    }
  prepared_.resize(map.objects.size());
  for (size_t j = 0; j < relevant.size(); ++j)
    if (relevant[j]) {
      relevant_.push_back(static_cast<int>(j));
      prepared_[j] = ProjectableEllipsoid(map.objects[j].ellipsoid);
    }
  // A match to an object that carried the observed label in only a minority of its detections
  // is worth that share of a match (full at a majority, share >= 0.5).
  label_weight_.resize(cands.size());
  for (size_t i = 0; i < cands.size(); ++i)
    for (int j : cands[i]) {
      const MapObject& m = map.objects[static_cast<size_t>(j)];
      const bool weigh = options.weigh_minority_labels && m.category != observations[i].category;
      label_weight_[i].push_back(weigh ? std::min(1.0, m.categoryShare(observations[i].category) / 0.5) : 1.0);
    }
  projected_.resize(map.objects.size());
  projected_box_.resize(map.objects.size());
  projects_.resize(map.objects.size(), 0);
  for (const Observation& o : observations) {
    observation_valid_.push_back(o.ellipse.isValid());
    observation_area_.push_back(o.ellipse.area());
    observation_box_.push_back(o.ellipse.boundingBox());
  }
  observation_taken_.resize(observations.size());
  object_taken_.resize(map.objects.size());
  pending_.reserve(64);
}

namespace {

/// Whether the image of an ellipsoid (centre c, largest semi-axis r) under a valid pose
/// certainly misses the boxes of the observations `which` (indices into `observations`): it lies
/// within the image of the sphere of radius r about c, whose bounding box comes from the planes
/// through the camera centre tangent to the sphere, u = (x z -+ r sqrt(x^2 + z^2 - r^2)) /
/// (z^2 - r^2) (camera coordinates; v likewise). `area` bounds those boxes, for a first test. A
/// pixel of margin keeps the test conservative under rounding.
bool certainlyOutside(const Eigen::Vector3d& c, double r, const Pose& pose, const Intrinsics& K, const Box& area,
                      const std::vector<int>& which, const std::vector<Observation>& observations) {
  const Eigen::Vector3d x = pose.transform(c);
  const double r2 = r * r, h = x(2) * x(2) - r2;
  if (!(x(2) > r)) return false;
  const double su = r * std::sqrt(x(0) * x(0) + h), sv = r * std::sqrt(x(1) * x(1) + h);
  const double u1 = (x(0) * x(2) - su) / h * K.fx + K.cx - 1.0, u2 = (x(0) * x(2) + su) / h * K.fx + K.cx + 1.0;
  const double v1 = (x(1) * x(2) - sv) / h * K.fy + K.cy - 1.0, v2 = (x(1) * x(2) + sv) / h * K.fy + K.cy + 1.0;
  const auto misses = [&](const Box& b) { return u2 <= b.x1 || b.x2 <= u1 || v2 <= b.y1 || b.y2 <= v1; };
  if (misses(area)) return true;
  for (const int i : which)
    if (!misses(observations[static_cast<size_t>(i)].box)) return false;
  return true;
}

/// Open pairs cost()'s give-up check may read per exact overlap computed (one exact overlap
/// costs about as much as reading a few hundred pairs).
constexpr size_t kPairsReadPerExactOverlap = 64;

}  // namespace

double PoseScorer::overlap(const Observation& o, const Ellipse& projected, int vertices) const {
  return options_.overlap == OverlapMeasure::BoxIoU ? boxIoU(o.box, projected.boundingBox())
                                                    : ellipseIoU(o.ellipse, projected, vertices);
}

bool PoseScorer::overlapMayReach(size_t i, const Ellipse& projected, int vertices, double threshold) const {
  // The margin absorbs the rounding between the bound and the exact overlap.
  return options_.overlap != OverlapMeasure::EllipseIoU ||
         ellipseBound(i, projected, projected.boundingBox(), vertices) >= threshold - 1e-9;
}

bool PoseScorer::overlapCertainlyReaches(const Observation& o, const Ellipse& projected, int vertices,
                                         double threshold) const {
  return options_.overlap == OverlapMeasure::EllipseIoU &&
         ellipseIoULowerBound(o.ellipse, projected, vertices) >= threshold + 1e-9;
}

template <typename F>
void PoseScorer::forEachNearbyPair(F f) const {
  for (size_t i = 0; i < observations_.size(); ++i) {
    if (!candidates_.usable[i]) continue;
    const Observation& o = observations_[i];
    const std::vector<int>& cands = candidates_.of_observation[i];
    for (size_t c = 0; c < cands.size(); ++c) {
      const int j = cands[c];
      if (!projects_[j]) continue;
      const Box& pb = projected_box_[j];
      if (pb.x2 <= o.box.x1 || o.box.x2 <= pb.x1 || pb.y2 <= o.box.y1 || o.box.y2 <= pb.y1) continue;
      f(i, c, j);
    }
  }
}

double PoseScorer::ellipseBound(size_t i, const Ellipse& projected, const Box& projected_box, int vertices) const {
  // ellipseIoUUpperBound(observations_[i].ellipse, projected, vertices), from the observation's
  // extents kept (a projection that succeeded is a valid ellipse).
  if (!observation_valid_[i]) return 0.0;
  return detail::iouUpperBoundFromExtents(observation_area_[i], observations_[i].ellipse.center(), observation_box_[i],
                                          projected.area(), projected.center(), projected_box, vertices);
}

double PoseScorer::pairBound(size_t i, int j, int vertices) const {
  if (options_.overlap == OverlapMeasure::BoxIoU) return boxIoU(observations_[i].box, projected_box_[j]);
  return ellipseBound(i, projected_[j], projected_box_[j], vertices);
}

double PoseScorer::costLowerBound(int vertices) {
  const double miss = options_.unmatched_cost;
  pair_bounds_.clear();
  best_gain_.assign(observations_.size(), 0.0);  // an observation left unmatched gains nothing
  forEachNearbyPair([&](size_t i, size_t c, int j) {
    const double ub = pairBound(i, j, vertices);
    pair_bounds_.push_back(ub);
    if (ub < options_.min_overlap - 1e-9) return;
    best_gain_[i] = std::max(best_gain_[i], miss - 1.0 + std::min(1.0, ub + 1e-9) * label_weight_[i][c]);
  });
  double bound = miss * candidates_.num_usable;
  for (double gain : best_gain_) bound -= gain;
  return bound;
}

double PoseScorer::gainStillPossible(const PendingPair& top) {
  // Each observation not yet matched gains at most its best pair still open (one whose object
  // is not taken either): by its exact credit, or by its bound until that is computed.
  std::fill(open_key_.begin(), open_key_.end(), -std::numeric_limits<double>::infinity());
  open_key_[static_cast<size_t>(top.observation)] = top.key;
  for (const PendingPair& q : pending_)
    if (!observation_taken_[q.observation] && !object_taken_[q.object])
      open_key_[static_cast<size_t>(q.observation)] = std::max(open_key_[static_cast<size_t>(q.observation)], q.key);
  const double miss = options_.unmatched_cost;
  double gain = 0.0;
  for (double key : open_key_) gain += std::max(0.0, miss - 1.0 + key);
  return gain;
}

double PoseScorer::cost(const Pose& pose, int vertices, std::vector<ObjectCorrespondence>* matches,
                        const KnownProjections* known, double give_up_at) {
  const std::optional<Eigen::Matrix<double, 3, 4>> P = projectionAt(pose);  // checked once, not per object
  for (int j : relevant_) {
    const int* k = known ? std::find(known->objects, known->objects + known->count, j) : nullptr;
    if (known && k != known->objects + known->count) {
      projects_[j] = 1;
      projected_[j] = known->ellipses[k - known->objects];
      projected_box_[j] = projected_[j].boundingBox();
      continue;
    }
    // Most objects are out of view at most poses: a cheap test spares their projection.
    const ProjectableEllipsoid& e = prepared_[static_cast<size_t>(j)];
    if (P && e.valid &&
        certainlyOutside(e.ellipsoid.center(), e.largest_axis, pose, K_, candidate_area_[static_cast<size_t>(j)],
                         candidate_observations_[static_cast<size_t>(j)], observations_)) {
      projects_[j] = 0;
      continue;
    }
    const Projection p = P ? projectPrepared(e, *P, pose) : Projection{};
    projects_[j] = p.ok();
    if (p.ok()) {
      projected_[j] = p.ellipse;
      projected_box_[j] = p.ellipse.boundingBox();
    }
  }
  // Most hypotheses are far worse than those kept: bounds show it without an exact overlap.
  const bool bounded = give_up_at < std::numeric_limits<double>::infinity();
  if (bounded && costLowerBound(vertices) - 1e-9 >= give_up_at) {
    if (matches) matches->clear();
    return std::numeric_limits<double>::infinity();
  }
  // Greedy one-to-one matching on credit, evaluated lazily: pairs leave a heap in order of
  // their credit, or of its upper bound until their exact overlap is computed. An exact pair on
  // top outranks every pair left, bounds included, so the matches and their order are those of
  // sorting every exact credit, without the exact overlaps of pairs whose observation or object
  // is taken before they come up. As exact credits replace bounds, the cost may be shown to
  // reach give_up_at before the matching ends: it gives up then, before the next exact overlap.
  pending_.clear();
  size_t pair = 0;  // the pairs come in the order costLowerBound kept their bounds in
  forEachNearbyPair([&](size_t i, size_t c, int j) {
    const double bound = bounded ? pair_bounds_[pair++] : pairBound(i, j, vertices);
    if (bound < options_.min_overlap - 1e-9) return;  // overlapMayReach's margin
    const double weight = label_weight_[i][c];
    // Raised by a rounding margin, so that no bound falls below its exact credit.
    pending_.push_back({std::min(1.0, bound) * weight + 1e-9, weight, static_cast<int>(i), j, false});
  });
  const auto ranksBelow = [](const PendingPair& a, const PendingPair& b) {
    if (a.key != b.key) return a.key < b.key;
    return a.observation != b.observation ? a.observation > b.observation : a.object > b.object;
  };
  std::make_heap(pending_.begin(), pending_.end(), ranksBelow);
  std::fill(observation_taken_.begin(), observation_taken_.end(), 0);
  std::fill(object_taken_.begin(), object_taken_.end(), 0);
  open_key_.resize(observations_.size());
  const double miss = options_.unmatched_cost;
  double total = miss * candidates_.num_usable;
  if (matches) matches->clear();
  size_t exact_since_check = 0;
  while (!pending_.empty()) {
    std::pop_heap(pending_.begin(), pending_.end(), ranksBelow);
    PendingPair p = pending_.back();
    pending_.pop_back();
    if (observation_taken_[p.observation] || object_taken_[p.object]) continue;
    if (!p.exact) {
      // The check reads every open pair: in frames of many pairs it runs only once per so many
      // exact overlaps that its reading stays a small share of theirs.
      if (bounded && ++exact_since_check * kPairsReadPerExactOverlap >= pending_.size()) {
        exact_since_check = 0;
        if (total - gainStillPossible(p) - 1e-9 >= give_up_at) {
          if (matches) matches->clear();
          return std::numeric_limits<double>::infinity();
        }
      }
      const double ov = overlap(observations_[p.observation], projected_[p.object], vertices);
      if (ov < options_.min_overlap) continue;
      p.overlap = ov;
      p.key = ov * p.weight;
      p.exact = true;
      pending_.push_back(p);
      std::push_heap(pending_.begin(), pending_.end(), ranksBelow);
      continue;
    }
    observation_taken_[p.observation] = object_taken_[p.object] = 1;
    total += (1.0 - p.key) - miss;
    if (matches) matches->push_back({p.observation, p.object, p.overlap, p.key});
  }
  return total;
}

}  // namespace ellreloc::pipeline
