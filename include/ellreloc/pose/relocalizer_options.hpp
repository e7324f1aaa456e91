#pragma once
/// \file relocalizer_options.hpp
/// The ObjectRelocalizer's options, one group per stage of its pipeline (docs/pose.md says what
/// each default was measured against):
///   search      which hypotheses are generated from triplets of candidate pairs, and the budgets
///   scoring     how a pose is scored against the observations (the one cost every stage uses)
///   few_objects poses from one or two objects for frames with few observations
///   gravity     how an optional gravity prior gates and joins the refinement
///   refinement  which hypotheses are refined, and how
/// validate() names the first field out of range; the relocalizer then answers InvalidInput.

#include <cmath>
#include <optional>
#include <string>

#include "ellreloc/core/camera_envelope.hpp"
#include "ellreloc/core/ransac.hpp"
#include "ellreloc/pose/few_object_poses.hpp"
#include "ellreloc/pose/wasserstein_refiner.hpp"

namespace ellreloc {

enum class HypothesisSampler {
  Auto,        ///< Exhaustive when there are at most `max_exhaustive_triplets` usable triplets, else Prosac
  Exhaustive,  ///< every triplet of candidate pairs (OA-SLAM)
  Uniform,     ///< random triplets
  Prosac,      ///< random triplets, best (detection score x object size) first
};

enum class OverlapMeasure {
  EllipseIoU,  ///< IoU of the observed ellipse and the projected ellipse
  BoxIoU,      ///< IoU of the observed box and the projected ellipse's bounding box (OA-SLAM)
};

/// Hypotheses from triplets of (observation, map object) pairs through P3P.
struct SearchOptions {
  HypothesisSampler sampler = HypothesisSampler::Auto;
  /// Auto enumerates every triplet when there are at most this many with three distinct
  /// observations (the triplets P3P is tried on).
  long max_exhaustive_triplets = 1000;
  bool correct_centres = true;  ///< re-solve P3P with the projected-centre offset removed
  /// In a sampled search (Uniform, Prosac), a P3P pose stays uncorrected when its correction
  /// fits the sample's own three observations worse (their W2^2 over the observed ellipse's
  /// size, as the refiner weighs a match) or fails the sample check where it passes: the
  /// correction now and then carries a pose to another P3P root, and a triplet drawn by chance
  /// may not be drawn again. An enumeration tries every triplet and keeps the corrected pose.
  /// Off by default: on real frames it found a few more poses for about a sixth more time,
  /// measured while the correction still jumped to far roots often (docs/pose.md, options).
  bool uncorrected_when_closer = false;
  /// Drop a pose when one of its own three pairs overlaps less than scoring.min_overlap: a
  /// wrong triplet rarely fits the three shapes, and this costs three overlaps, not a map.
  bool check_sample_overlap = true;
  /// A sampled search (Uniform, Prosac) ends early once its best hypothesis explains every
  /// usable observation, at least four of them, with a mean credit (overlap, weighed by label as
  /// the cost is: 1 - its cost per observation) of at least `explained_mean_credit`: it draws
  /// as many samples again (budget.enough_extension) and stops: no pose can explain more,
  /// and the adaptive count, reading inliers over every candidate pair, would go on as if at most
  /// one pair in twelve could be right where each observation has twelve look-alike candidates.
  /// Enumeration never stops early. (budget.enough_inliers and enough_score are set per frame.)
  bool stop_when_explained = true;
  double explained_mean_credit = 0.7;
  /// A hypothesis that explains every usable observation, at least four, but with a mean
  /// credit below `explained_mean_credit` is refined on its matches (the refinement stage's
  /// refiner, once) and scored again; the better of the two is the hypothesis (local
  /// optimisation, Chum et al., DAGM 2003). A P3P pose from three box centres is centimetres
  /// off; refined, it often reaches the credit that ends a sampled search thousands of samples
  /// before a raw pose does.
  bool refine_explained = true;
  /// Sample and hypothesis budgets, adaptive stopping and seed. The Exhaustive sampler
  /// enumerates every triplet: only max_hypotheses and max_time_ms bound it.
  RansacOptions budget;
  /// A machine-independent bound on the work: scoring a hypothesis costs up to one overlap per
  /// (map object, usable observation) pair, so max_hypotheses shrinks to this many overlaps
  /// over that product. 0: no bound.
  long max_overlap_evaluations = 40000000;
  /// At most this many (observation, candidate object) pairs are formed, so that memory stays
  /// bounded (about 100 bytes a pair) whatever the frame and map: beyond it the least confident
  /// observations are left out (RelocalizationResult::skipped says so).
  long max_candidate_pairs = 1000000;
  /// Threads that generate and score one frame's triplet hypotheses (core/ransac.hpp,
  /// ransacOnThreads): the same result whatever the count. For a host that relocalizes one frame
  /// at a time; many frames at once gain more from a thread per frame.
  int threads = 1;

  SearchOptions() {
    budget.min_iterations = 50;
    budget.max_iterations = 20000;
    budget.max_hypotheses = 50000;
    budget.max_time_ms = 0.0;  // a time budget makes results depend on the machine: off by default
    budget.success_probability = 0.999;
    budget.skip_repeated_samples = true;  // P3P gives the same poses in any order of the pairs, to rounding
  }
};

/// The cost of a pose: observations and projected map objects matched one to one (greedy on
/// overlap); a match costs 1 - overlap x label weight, an observation left out `unmatched_cost`.
struct ScoringOptions {
  OverlapMeasure overlap = OverlapMeasure::EllipseIoU;
  /// Below this overlap there is no match. Low, because a true match between an inexact map
  /// and a box-inscribed ellipse often overlaps little.
  double min_overlap = 0.15;
  /// At 1 every match is worth more than a miss, so a pose that explains more objects
  /// moderately beats one that explains fewer very well.
  double unmatched_cost = 1.0;
  /// An object is a candidate for an observation of category c when at least this share of its
  /// mapped detections carried c (MapObject::categoryShare); without a label histogram only
  /// equal categories match. Above 0.5 only the majority label matches.
  double min_category_share = 0.05;
  /// A match through a minority label (share below 0.5) counts as share / 0.5 of a match.
  bool weigh_minority_labels = true;
  /// Fewer matched observations: no consistent hypothesis. Two objects constrain a pose (10
  /// equations, 6 unknowns); a frame with one usable observation needs gravity and one suffices.
  int min_inliers = 2;
};

/// Poses from one or two objects (few_object_poses.hpp): frames with few usable observations,
/// and frames where no triplet explains three.
struct FewObjectSearchOptions {
  bool enabled = true;
  /// With at most this many usable observations, pairs are tried besides triplets.
  int max_observations = 2;
  long max_pair_hypotheses = 200;  ///< pairs of candidate pairs given to the two-object solver
  FewObjectOptions solver;
};

/// What a gravity prior (relocalize(..., gravity)) does besides giving one-object poses.
struct GravityOptions {
  /// Hypotheses tilted more than max(gate_deg, 5 sigma) from the prior are dropped: loose,
  /// because a P3P pose from three box centres is often 5-10 degrees off before refinement.
  double gate_deg = 15.0;
  /// Also use the prior when refining poses that rest on three or more objects (by default
  /// only poses on fewer objects, whose tilt the objects constrain weakly).
  bool in_every_refinement = false;
};

/// The best distinct hypotheses are refined with the Wasserstein refiner on all their matches.
struct RefinementStageOptions {
  bool enabled = true;
  int top_k = 10;            ///< distinct hypotheses kept for refinement (the best raw one often refines worse)
  double cost_margin = 3.0;  ///< ... of which only those within this cost of the best are refined
  int rounds = 3;            ///< refine, match again at the refined pose, refine again while observations join
  /// The expected error of an ellipse fitted to a regular mask relative to a box's ellipse:
  /// its residual is divided by this (EllipseMatch::sigma), so it weighs (1/0.7)^2 = 2 times as
  /// much. The fit alone is about half as far from the object's projection as the box
  /// (docs/benchmarks.md, scene tables); the map's own error, the same for both, brings the
  /// ratio of the whole errors to about 0.7. 1 weighs every observation alike.
  double regular_mask_sigma = 0.7;
  /// The chosen pose is refined once more on its matches with this Cauchy scale (normalised W2
  /// units, as RefinerOptions::object_loss_scale) and kept when it explains the observations at
  /// least as well: the tighter loss lets a few matches that disagree with the rest (a partly
  /// hidden object, a box of part of one, a misplaced map object) pull the pose less, once the
  /// matches are settled. The wider `refiner` scale stays for choosing among the hypotheses,
  /// where a tight loss would let a wrong pose ignore what it does not explain. 0: off.
  double polish_loss_scale = 0.3;
  RefinerOptions refiner;
};

/// Whether the observations support the chosen pose enough to report it. The evidence of a
/// pose is the sum of its matches' overlaps minus `unexplained_penalty` per usable observation
/// it leaves unexplained. Poses below `min_evidence` get LowEvidence, not Success: calibrated on
/// frames of random boxes of the maps' categories and on frames of one scene against another
/// scene's map (docs/reliability.md), of which 1% pass; at 2.3 a pose needs at least three
/// matches, so frames with fewer usable observations are not searched (NotEnoughObservations):
/// a host that checks poses itself turns the test off to get theirs.
struct AcceptanceOptions {
  bool enabled = true;
  double min_evidence = 2.3;
  double unexplained_penalty = 0.5;
  /// Poses whose margin over their best rival (RelocalizationResult::margin) is below this get
  /// LowEvidence too. 0 keeps every margin; 0.1 to 0.3 trade a few valid poses for many fewer
  /// wrong ones on real data, where wrong poses are ambiguous ones (docs/reliability.md).
  double min_margin = 0.0;
};

struct RelocalizerOptions {
  SearchOptions search;
  ScoringOptions scoring;
  FewObjectSearchOptions few_objects;
  GravityOptions gravity;
  RefinementStageOptions refinement;
  AcceptanceOptions acceptance;
  /// Where the camera can be (camera_envelope.hpp, e.g. from the mapping keyframes): poses
  /// outside are never hypotheses. None: what `map_envelope` takes from the map, else anywhere.
  std::optional<CameraEnvelope> envelope;
  /// Without `envelope`, keep the camera where the map says: within its camera_envelope when it
  /// has one (maps built by the Mapper record where their keyframes were taken), else upright
  /// (image-up within 90 degrees of up, image rows within 45 of level, any height) about the up
  /// its objects tell when they tell it clearly (estimateMapUp, map_up.hpp), else anywhere.
  bool map_envelope = true;

  /// OA-SLAM's relocalization as a baseline: every detection triplet against every object
  /// triplet of equal categories, P3P on box centres, box-IoU scoring, no refinement. Give it
  /// box-inscribed observations (observationFromBox).
  static RelocalizerOptions oaSlam() {
    RelocalizerOptions o;
    o.search.sampler = HypothesisSampler::Exhaustive;
    o.search.correct_centres = false;
    o.search.check_sample_overlap = false;
    o.search.stop_when_explained = false;
    o.search.refine_explained = false;
    o.search.budget.max_hypotheses = 1L << 40;
    // The baseline enumerates everything real frames offer (at most 4.3e7 overlaps on fr2_desk
    // and fr3/long_office frames), but stays bounded on absurd input.
    o.search.max_overlap_evaluations = 200000000;
    o.scoring.overlap = OverlapMeasure::BoxIoU;
    o.scoring.min_category_share = 1.0;  // equal (majority) categories only
    o.scoring.min_inliers = 3;
    o.scoring.min_overlap = 0.25;
    o.scoring.unmatched_cost = 1.0 - o.scoring.min_overlap;  // a weak match is worth nothing
    o.few_objects.enabled = false;
    o.refinement.enabled = false;
    o.refinement.top_k = 1;
    o.acceptance.enabled = false;  // OA-SLAM reports every pose it finds
    o.map_envelope = false;        // nor does it keep the camera where the map was made
    return o;
  }

  /// Empty when every field is in range, else one line naming the first field that is not.
  std::string validate() const {
    const auto finite = [](double x) { return std::isfinite(x); };
    if (search.max_exhaustive_triplets < 0) return "search.max_exhaustive_triplets is negative";
    if (search.budget.min_iterations < 0 || search.budget.max_iterations < 0)
      return "search.budget iteration counts are negative";
    if (search.budget.max_hypotheses < 0) return "search.budget.max_hypotheses is negative";
    if (!finite(search.budget.max_time_ms) || search.budget.max_time_ms < 0)
      return "search.budget.max_time_ms is negative or not finite";
    if (!(search.budget.success_probability > 0 && search.budget.success_probability < 1))
      return "search.budget.success_probability is not in (0, 1)";
    if (!(search.budget.enough_extension >= 0 && search.budget.enough_extension <= 1e6))
      return "search.budget.enough_extension is not in [0, 1e6]";
    if (!(search.explained_mean_credit >= 0 && search.explained_mean_credit <= 1))
      return "search.explained_mean_credit is not in [0, 1]";
    if (search.max_overlap_evaluations < 0) return "search.max_overlap_evaluations is negative";
    if (search.max_candidate_pairs < 1) return "search.max_candidate_pairs is below 1";
    if (search.threads < 1 || search.threads > 256) return "search.threads is not in [1, 256]";
    if (!(scoring.min_overlap >= 0 && scoring.min_overlap <= 1)) return "scoring.min_overlap is not in [0, 1]";
    if (!(finite(scoring.unmatched_cost) && scoring.unmatched_cost >= 0))
      return "scoring.unmatched_cost is negative or not finite";
    if (!(scoring.min_category_share >= 0 && scoring.min_category_share <= 1))
      return "scoring.min_category_share is not in [0, 1]";
    if (scoring.min_inliers < 1) return "scoring.min_inliers is below 1";
    if (few_objects.max_observations < 0 || few_objects.max_pair_hypotheses < 0)
      return "few_objects.max_observations or few_objects.max_pair_hypotheses is negative";
    if (few_objects.solver.angle_steps < 1 || !(few_objects.solver.axis_step_deg > 0) ||
        !finite(few_objects.solver.axis_step_deg) || few_objects.solver.max_poses < 0)
      return "few_objects.solver has a non-positive step or a negative pose count";
    if (!(finite(gravity.gate_deg) && gravity.gate_deg >= 0)) return "gravity.gate_deg is negative or not finite";
    if (refinement.top_k < 1 || refinement.rounds < 0) return "refinement.top_k below 1 or refinement.rounds negative";
    if (!(refinement.cost_margin >= 0)) return "refinement.cost_margin is negative or not a number";
    if (!(finite(refinement.regular_mask_sigma) && refinement.regular_mask_sigma > 0))
      return "refinement.regular_mask_sigma is not a positive number";
    if (!(finite(refinement.polish_loss_scale) && refinement.polish_loss_scale >= 0))
      return "refinement.polish_loss_scale is negative or not finite";
    const RefinerOptions& r = refinement.refiner;
    if (!(finite(r.object_loss_scale) && r.object_loss_scale > 0) ||
        !(finite(r.point_sigma_px) && r.point_sigma_px > 0) ||
        !(finite(r.point_loss_scale) && r.point_loss_scale > 0) || !(finite(r.point_weight) && r.point_weight >= 0))
      return "refinement.refiner has a non-positive or non-finite scale or weight";
    if (r.max_iterations < 0 || !(r.function_tolerance >= 0))
      return "refinement.refiner has a negative tolerance or count";
    if (!std::isfinite(acceptance.min_evidence) ||
        !(std::isfinite(acceptance.unexplained_penalty) && acceptance.unexplained_penalty >= 0))
      return "acceptance.min_evidence is not finite or acceptance.unexplained_penalty is negative";
    if (!(std::isfinite(acceptance.min_margin) && acceptance.min_margin >= 0))
      return "acceptance.min_margin is negative or not finite";
    if (envelope && !envelope->isValid())
      return "envelope has a non-unit or non-finite up, an empty or non-finite range, or a roll bound outside (0, 90]";
    return "";
  }
};

}  // namespace ellreloc
