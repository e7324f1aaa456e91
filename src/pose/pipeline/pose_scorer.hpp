#pragma once
// The one cost of the relocalization pipeline: every stage (sample checks, RANSAC, the few-object
// poses, refinement, scorePose) ranks poses with it.

#include <algorithm>
#include <limits>
#include <optional>
#include <vector>

#include "candidates.hpp"
#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"

namespace ellreloc::pipeline {

/// Vertices of the polygon ellipseIoU uses while ranking hypotheses (IoU error ~1e-2, ample to
/// rank poses and 3x faster than 128); the refinement and the result use kReportIoUVertices.
constexpr int kRankingIoUVertices = 32;
constexpr int kReportIoUVertices = 128;

/// What a pose's matches are worth as evidence among `usable` observations (AcceptanceOptions):
/// their overlaps, less the penalty per usable observation they leave unexplained.
inline double matchEvidence(const std::vector<ObjectCorrespondence>& matches, int usable,
                            const AcceptanceOptions& acceptance) {
  double sum = 0.0;
  for (const ObjectCorrespondence& m : matches) sum += m.overlap;
  return sum - acceptance.unexplained_penalty * std::max(0, usable - static_cast<int>(matches.size()));
}

/// Projections already computed at the pose being scored (a hypothesis's own objects).
struct KnownProjections {
  int count = 0;
  int objects[3] = {0, 0, 0};
  Ellipse ellipses[3];
};

/// Scores poses: projects the candidate objects and matches them one to one to the
/// observations. Holds scratch buffers: one scorer per call, never shared between threads.
class PoseScorer {
 public:
  PoseScorer(const std::vector<Observation>& observations, const Candidates& candidates, const ObjectMap& map,
             const Intrinsics& K, const ScoringOptions& options);

  /// The overlap of an observation and a projected ellipse under the options' measure.
  double overlap(const Observation& o, const Ellipse& projected, int vertices) const;
  /// False when the upper bound of the overlap of observation i and `projected` (a projection
  /// that succeeded) already shows that it is below `threshold`.
  bool overlapMayReach(size_t i, const Ellipse& projected, int vertices, double threshold) const;
  /// False when the image of map object j at `pose` is certainly too large or too small to
  /// overlap observation o by `threshold` under the ellipse IoU, which is at most the ratio of the
  /// two areas (imageAreaBounds: no projection). j must be a candidate of some observation.
  bool sizeMayReach(const Observation& o, int j, const Pose& pose, double threshold) const {
    if (options_.overlap != OverlapMeasure::EllipseIoU) return true;
    const ImageAreaBounds b = imageAreaBounds(prepared_[static_cast<size_t>(j)], K_, pose);
    const double area = o.ellipse.area();
    return !(area < threshold * b.lower * (1 - 1e-9) || threshold * area > b.upper * (1 + 1e-9));
  }
  /// True when the overlap's lower bound already shows that it reaches `threshold`.
  bool overlapCertainlyReaches(const Observation& o, const Ellipse& projected, int vertices, double threshold) const;

  /// The cost of a pose: unmatched_cost per usable observation, less (unmatched_cost - (1 -
  /// credit)) per one-to-one match, greedy on credit. Fills the matches when asked. When a lower
  /// bound of the cost (each observation credited with the best overlap bound of its projected
  /// candidates) already reaches `give_up_at`, returns infinity without the exact overlaps.
  double cost(const Pose& pose, int vertices, std::vector<ObjectCorrespondence>* matches = nullptr,
              const KnownProjections* known = nullptr, double give_up_at = std::numeric_limits<double>::infinity());

  /// projectionMatrix(K, pose), or nullopt for invalid intrinsics or pose (nothing projects):
  /// computed once for the objects of a pose.
  std::optional<Eigen::Matrix<double, 3, 4>> projectionAt(const Pose& pose) const {
    if (!K_.isValid() || !pose.isValid()) return std::nullopt;
    return projectionMatrix(K_, pose);
  }

  /// project(map object j, K, pose), with the object's quantities computed once; j must be a
  /// candidate of some observation, P = *projectionAt(pose).
  Projection projectObject(int j, const Eigen::Matrix<double, 3, 4>& P, const Pose& pose) const {
    return projectPrepared(prepared_[static_cast<size_t>(j)], P, pose);
  }

  /// The centre of projectObject(j, P, pose)'s ellipse, computed alone (projectedCentre).
  std::optional<Eigen::Vector2d> projectedCentre(int j, const Eigen::Matrix<double, 3, 4>& P) const {
    return ellreloc::projectedCentre(prepared_[static_cast<size_t>(j)], P);
  }

  const ScoringOptions& options() const { return options_; }

 private:
  /// f(observation i, candidate c, object j) for each usable observation's candidates that
  /// project with a box overlapping the observation's, in a fixed order.
  template <typename F>
  void forEachNearbyPair(F f) const;
  /// An upper bound of the overlap of observation i and object j's current projection (under
  /// box IoU, the overlap itself): a few operations.
  double pairBound(size_t i, int j, int vertices) const;
  /// ellipseIoUUpperBound of observation i's ellipse and a successful projection with its box.
  double ellipseBound(size_t i, const Ellipse& projected, const Box& projected_box, int vertices) const;
  /// unmatched_cost per usable observation less, for each, the most its best projected
  /// candidate could gain by the overlap bound: no exact overlap is computed. Keeps each pair's
  /// bound (pair_bounds_, in forEachNearbyPair's order) for the exact pass.
  double costLowerBound(int vertices);
  /// A pair waiting in cost()'s matching: key is its credit once exact, else the credit's bound.
  struct PendingPair {
    double key, weight;
    int observation, object;
    bool exact;
    double overlap = 0.0;
  };
  /// During cost()'s matching, with `top` just taken off the heap: the most the observations
  /// not yet matched could still take off the cost.
  double gainStillPossible(const PendingPair& top);
  const std::vector<Observation>& observations_;
  const Candidates& candidates_;
  const Intrinsics& K_;
  const ScoringOptions& options_;
  std::vector<int> relevant_;                             // objects that are some observation's candidate
  std::vector<ProjectableEllipsoid> prepared_;            // per map object (filled for the relevant ones)
  std::vector<Box> candidate_area_;                       // per map object: the union of its observations' boxes
  std::vector<std::vector<int>> candidate_observations_;  // per map object: the observations it may explain
  std::vector<std::vector<double>> label_weight_;         // per observation, per candidate
  // Per observation: what the overlap bounds read of its ellipse.
  std::vector<char> observation_valid_;
  std::vector<double> observation_area_;
  std::vector<Box> observation_box_;
  // Scratch, reused across calls.
  std::vector<Ellipse> projected_;
  std::vector<Box> projected_box_;  // the bounding box of each projected_ ellipse
  std::vector<char> projects_;
  std::vector<PendingPair> pending_;
  std::vector<char> observation_taken_, object_taken_;
  std::vector<double> pair_bounds_, best_gain_, open_key_;
};

}  // namespace ellreloc::pipeline
