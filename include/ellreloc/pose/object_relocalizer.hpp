#pragma once
/// \file object_relocalizer.hpp
/// Camera relocalization from one image's object observations and a map of ellipsoids: the
/// paper's "initial pose recovery" (a P3P loop over ellipse-ellipsoid correspondences) and
/// "pose refinement" (Wasserstein), as one call.
///
/// Hypotheses are triplets of (observation, map object) pairs of equal category. P3P on the
/// observed ellipse centres and the ellipsoid centres gives up to four poses; the P3P input is
/// then corrected for the offset between the centre of a projected ellipsoid's ellipse and the
/// projection of its centre, and solved again. Each pose is scored by projecting the map and
/// matching projections to observations one to one (same category, greedy on overlap) with a
/// bounded cost: 1 - overlap per match (overlap >= min_overlap), `unmatched_cost` per
/// observation left out, so a wrong or missed detection costs at most a constant. The best few distinct hypotheses are
/// refined with the Wasserstein refiner on all their inliers and rescored.
///
/// Frames with few observations: with at most `pair_search_max_observations` usable
/// observations (or when no triplet explains three of them), pairs of (observation, object)
/// pairs also give poses through the two-object solver (few_object_poses.hpp), so a frame
/// with two detections, or with three of which one is wrong, still gets a pose. With a
/// gravity prior, a single observation gives poses too (one object + gravity), and every
/// hypothesis whose tilt disagrees with gravity is dropped.

#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/object_map.hpp"
#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/observation.hpp"
#include "ellreloc/pose/few_object_poses.hpp"
#include "ellreloc/pose/gravity_prior.hpp"
#include "ellreloc/core/ransac.hpp"
#include "ellreloc/pose/wasserstein_refiner.hpp"

namespace ellreloc {

enum class HypothesisSampler {
  Auto,        ///< Exhaustive when there are at most `max_exhaustive_triplets` triplets, else Prosac
  Exhaustive,  ///< every triplet of candidate pairs (OA-SLAM)
  Uniform,     ///< random triplets
  Prosac,      ///< random triplets, best (detection score x object size) first
};

enum class OverlapMeasure {
  EllipseIoU,  ///< IoU of the observed ellipse and the projected ellipse
  BoxIoU,      ///< IoU of the observed box and the projected ellipse's bounding box (OA-SLAM)
};

struct RelocalizerOptions {
  HypothesisSampler sampler = HypothesisSampler::Auto;
  long max_exhaustive_triplets = 1000;
  OverlapMeasure overlap = OverlapMeasure::EllipseIoU;
  /// A match below this overlap is no match (the cost's truncation). Low, because a true match
  /// of an inexact map and a box-inscribed ellipse often overlaps little: 0.15 did better than
  /// 0.25 both on the real fr2_desk map (64.1% valid against 61.1%) and on the simulated
  /// office with a perturbed map (97.0% against 93.0%).
  double min_overlap = 0.15;
  /// Cost of an observation left unmatched; a match costs 1 - overlap. At 1, every match
  /// (overlap >= min_overlap) is worth more than a miss, so a pose that explains more
  /// objects moderately beats one that explains fewer very well: on an inexact map the true
  /// pose is often the former (simulated cluttered scene: 9 -> 6 failures of 200 against
  /// 1 - min_overlap, where a weak match was worth nothing).
  double unmatched_cost = 1.0;
  /// An object is a candidate for an observation of category c when at least this share of
  /// its mapped detections carried c (MapObject::categoryShare): detectors confuse cups with
  /// mice and books with plants, and maps that keep a label histogram know it. With no
  /// histogram only equal categories match. Above 0.5, only the majority label matches.
  double min_category_share = 0.05;
  /// A match through a minority label (the object's share of it below 0.5) counts as that
  /// fraction of 0.5 in the score: a cup matched to a mug-shaped object whose detections were
  /// 10% "cup" is weaker evidence than one matched to a "cup". fr2_desk: 65.2% -> 66.7% valid;
  /// no change on the simulated scenes (their maps carry no label histograms).
  bool weigh_minority_labels = true;
  /// Fewer matched observations: no consistent hypothesis. Two objects constrain a pose
  /// (their ellipses give 10 equations for 6 unknowns); a frame with a single usable
  /// observation needs a gravity prior and then one suffices.
  int min_inliers = 2;
  /// Poses from one or two objects (few_object_poses.hpp) for frames with few observations.
  bool few_object_solvers = true;
  /// With at most this many usable observations, pairs are tried besides triplets (they are
  /// also tried when no triplet explains three observations). Raising it to 3 or 4 rescues
  /// frames where one of three or four detections is wrong, but a pose fitted to two objects
  /// can then outscore the right one on an inexact map: on fr2_desk 2 did best (docs/benchmarks.md).
  int pair_search_max_observations = 2;
  long max_pair_hypotheses = 200;  ///< pairs of candidate pairs given to the two-object solver
  FewObjectOptions few_object;
  /// With a gravity prior, hypotheses tilted more than max(gravity_gate_deg, 5 sigma) from
  /// it are dropped: loose, because a P3P pose from three box centres is often 5-10 degrees
  /// off before refinement.
  double gravity_gate_deg = 15.0;
  /// Also use the gravity prior when refining poses that rest on three or more objects. On
  /// an exact map this costs accuracy (the IMU's noise enters the pose: 0.19 -> 0.52 deg on
  /// the synthetic room with a 1 deg IMU); on an inexact map it helps (fr2_desk with a
  /// simulated IMU: 75.8% -> 76.3% valid). Off: objects, when there are enough, fix the tilt.
  bool gravity_in_every_refinement = false;
  bool correct_centres = true;  ///< re-solve P3P with the projected-centre offset removed
  /// Drop a pose at once when one of its own three pairs overlaps less than min_overlap:
  /// P3P fits the centres exactly, but a wrong triplet rarely fits the three shapes, and this
  /// costs three overlaps instead of scoring the whole map.
  bool check_sample_overlap = true;
  /// Distinct hypotheses refined with the Wasserstein refiner: the best-scoring raw
  /// hypothesis is often not the one that refines best (10 against 3: simulated office
  /// 5 -> 3 failures of 200, fr2_desk 64.1% -> 65.2% valid, ~0.5 ms more per query).
  int refine_top_k = 10;
  /// ... of which only those within this cost of the best: a hypothesis that explains three
  /// observations fewer than the best one does not win after refinement (none did on the
  /// benchmarks), and skipping it halves the time of an easy query (47 x 12: 4.2 -> 1.9 ms).
  double refine_cost_margin = 3.0;
  /// Refine, match again at the refined pose, and refine again while observations join.
  int refine_rounds = 3;
  bool refine = true;
  RefinerOptions refiner;
  RansacOptions ransac;  ///< budgets, adaptive stopping, seed
  /// A machine-independent bound on the work: the hypothesis budget shrinks to this many
  /// overlaps over (map objects x usable observations), but not below min_hypotheses_budget.
  /// 40e6 leaves the 50,000 hypotheses untouched up to 800 object-observation pairs (47
  /// objects x 17 observations) and gives 4,000 for 200 objects x 50 observations. 0: no bound.
  long max_overlap_evaluations = 40000000;
  long min_hypotheses_budget = 1000;

  RelocalizerOptions() {
    ransac.min_iterations = 50;
    ransac.max_iterations = 20000;
    ransac.max_hypotheses = 50000;
    ransac.max_time_ms = 0.0;  // a time budget makes results depend on the machine: off by default
    ransac.success_probability = 0.999;
    ransac.refine = false;  // the relocalizer refines its top hypotheses itself
  }

  /// OA-SLAM's relocalization as a baseline: every detection triplet against every object
  /// triplet of equal categories, P3P on box centres, box-IoU scoring, no refinement. Give it
  /// box-inscribed observations (observationFromBox).
  static RelocalizerOptions oaSlam() {
    RelocalizerOptions o;
    o.sampler = HypothesisSampler::Exhaustive;
    o.overlap = OverlapMeasure::BoxIoU;
    o.correct_centres = false;
    o.check_sample_overlap = false;
    o.min_category_share = 1.0;  // equal (majority) categories only
    o.min_inliers = 3;
    o.few_object_solvers = false;
    o.min_overlap = 0.25;
    o.unmatched_cost = 1.0 - o.min_overlap;  // a weak match is worth nothing
    o.refine = false;
    o.refine_top_k = 1;
    o.ransac.min_iterations = 1 << 30;  // enumerate everything, no adaptive stop
    o.ransac.max_iterations = 1 << 30;
    o.ransac.max_hypotheses = 1L << 40;
    o.ransac.max_time_ms = 0.0;
    o.max_overlap_evaluations = 0;  // the baseline enumerates everything
    return o;
  }
};

enum class RelocalizationStatus {
  Success,
  NotEnoughObservations,   ///< too few usable observations with a candidate object (see RelocalizerOptions)
  NoConsistentHypothesis,  ///< no pose explains at least min_inliers observations
  InvalidInput,            ///< invalid intrinsics or gravity prior
};

const char* toString(RelocalizationStatus s);

struct ObjectCorrespondence {
  int observation = 0;   ///< index into the observations given
  int object = 0;        ///< index into map.objects
  double overlap = 0.0;  ///< at the returned pose
};

struct RelocalizationResult {
  RelocalizationStatus status = RelocalizationStatus::NotEnoughObservations;
  std::string reason;  ///< human-readable, one line
  Pose pose;           ///< valid when status == Success
  std::vector<ObjectCorrespondence> inliers;
  double cost = 0.0;                                 ///< truncated overlap cost of the pose (lower is better)
  double mean_overlap = 0.0;                         ///< over the inliers
  std::vector<std::pair<int, std::string>> skipped;  ///< observations not used, with the reason
  long hypotheses = 0;
  int iterations = 0;
  bool budget_exhausted = false;
  bool refined = false;
  long few_object_hypotheses = 0;  ///< poses from the one- and two-object solvers (also in `hypotheses`)
  double time_ms = 0.0;
};

/// Holds a map and intrinsics; relocalize() is const and keeps no state, so one relocalizer
/// can serve many threads at once.
class ObjectRelocalizer {
 public:
  ObjectRelocalizer(ObjectMap map, const Intrinsics& K, RelocalizerOptions options = {});

  RelocalizationResult relocalize(const std::vector<Observation>& observations) const;
  /// The same, with the frame's 2D feature matches to the map's points (the host SLAM system's
  /// matcher output, outliers included): they join the Wasserstein refinement of the best
  /// hypotheses ("objects + points", robust point loss). A refined pose is kept when it
  /// explains at least as many observations as before. Keypoints whose index is outside
  /// map().points or that are not finite are ignored.
  RelocalizationResult relocalize(const std::vector<Observation>& observations,
                                  const std::vector<Keypoint>& keypoints) const;
  /// The same, with the direction of gravity in the camera (an IMU) and in the map: it drops
  /// hypotheses that tilt the camera wrongly, lets a single observation give a pose, and
  /// joins the refinement of poses that rest on fewer than three objects (with three or more
  /// the objects fix the tilt better than an IMU prior does). An invalid prior (zero or
  /// non-finite) is an InvalidInput status.
  RelocalizationResult relocalize(const std::vector<Observation>& observations, const std::vector<Keypoint>& keypoints,
                                  const std::optional<GravityPrior>& gravity) const;

  /// Scores a pose from elsewhere (tracking, odometry, another relocalizer) the way
  /// relocalize() scores its hypotheses: one-to-one matches, their overlaps and the truncated
  /// cost, with Success when it explains min_inliers observations (fewer if fewer are usable).
  RelocalizationResult scorePose(const std::vector<Observation>& observations, const Pose& pose) const;

  const ObjectMap& map() const { return map_; }
  const Intrinsics& intrinsics() const { return K_; }
  const RelocalizerOptions& options() const { return options_; }

 private:
  ObjectMap map_;
  Intrinsics K_;
  RelocalizerOptions options_;
};

}  // namespace ellreloc
