#pragma once
/// \file object_relocalizer.hpp
/// Camera relocalization from one image's object observations and a map of ellipsoids: the
/// paper's "initial pose recovery" (a P3P loop over ellipse-ellipsoid correspondences) and
/// "pose refinement" (Wasserstein), as one call.
///
/// relocalize() runs a pipeline (src/pose/pipeline/, docs/pose.md):
///   candidates   each observation's possible map objects (category or label histogram)
///   hypotheses   P3P on triplets of candidate pairs in a RANSAC loop, with the projected-centre
///                correction; for frames with few observations also the two-object solver on
///                pairs, and with gravity the one-object solver (few_object_poses.hpp)
///   pool         the best distinct hypotheses under one cost: observations and projected map
///                objects matched one to one, 1 - overlap per match, `unmatched_cost` per
///                observation left out, so a wrong or missed detection costs at most a constant
///   refine       the pooled hypotheses refined with the Wasserstein refiner on all their
///                matches, re-matched and refined again while observations join
///   result       the lowest-cost pose, its matches and statistics; LowEvidence instead of
///                Success when the matches support it too weakly (acceptance)
/// A gravity prior drops every hypothesis whose tilt disagrees with it and lets a single
/// observation give poses; a pose region (the host's last tracked pose) drops every hypothesis
/// outside it.

#include <chrono>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/map_up.hpp"
#include "ellreloc/core/object_map.hpp"
#include "ellreloc/core/observation.hpp"
#include "ellreloc/core/pose.hpp"
#include "ellreloc/pose/gravity_prior.hpp"
#include "ellreloc/pose/pose_region.hpp"
#include "ellreloc/pose/relocalizer_options.hpp"

namespace ellreloc {

enum class RelocalizationStatus {
  Success,
  NotEnoughObservations,   ///< too few usable observations with a candidate object for the solvers, or to
                           ///< reach acceptance.min_evidence (see RelocalizerOptions)
  NoConsistentHypothesis,  ///< no pose explains at least scoring.min_inliers observations
  InvalidInput,            ///< invalid intrinsics, gravity prior, pose region or options
  /// A pose was found but the observations support it too weakly (RelocalizationResult::evidence
  /// below acceptance.min_evidence, or its margin below acceptance.min_margin): frames of random
  /// boxes get such poses. `pose` and `inliers` hold it, for a host that can check it otherwise
  /// (e.g. with points).
  LowEvidence,
};

const char* toString(RelocalizationStatus s);

/// An observation matched to a map object at a pose.
struct ObjectCorrespondence {
  int observation = 0;   ///< index into the observations given
  int object = 0;        ///< index into map.objects
  double overlap = 0.0;  ///< at the pose
  double credit = 0.0;   ///< what the match is worth in the cost: overlap x label weight
};

struct RelocalizationResult {
  RelocalizationStatus status = RelocalizationStatus::NotEnoughObservations;
  std::string reason;  ///< human-readable, one line
  Pose pose;           ///< valid when status == Success
  std::vector<ObjectCorrespondence> inliers;
  double cost = 0.0;          ///< truncated overlap cost of the pose (lower is better)
  double mean_overlap = 0.0;  ///< over the inliers
  /// Sum of the inliers' overlaps minus half a point per usable observation left unexplained
  /// (AcceptanceOptions).
  double evidence = 0.0;
  /// How much higher the cost of the best rival is: of the hypotheses refined, the best one
  /// whose pose is another answer (at least kValidPositionCm or kValidRotationDeg away). Near 0
  /// when look-alike objects or a symmetric layout fit two poses alike; infinity when every
  /// refined hypothesis agreed with the pose, or only one was refined (the OA-SLAM preset, or a
  /// spent search.budget.max_time_ms). Rivals are the hypotheses the search found: a sampled
  /// search (beyond search.max_exhaustive_triplets) may stop before meeting one, and the margin
  /// is then too high.
  double margin = std::numeric_limits<double>::infinity();
  /// That rival's pose (world->camera), when there was one: a host that checks poses with its
  /// points can try it when `pose` fails the check. The first of `alternatives`.
  std::optional<Pose> rival;
  /// Every other answer among the hypotheses refined (world->camera poses and their costs),
  /// cheapest first: each at least kValidPositionCm or kValidRotationDeg away from the pose and
  /// from every cheaper one. For a host that checks poses with its points, the ones to try in
  /// turn when `pose` fails; empty when `rival` is none.
  std::vector<ScoredPose> alternatives;
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
  /// Objects of `map` that cannot be used (mapObjectProblem: degenerate or absurd semi-axes,
  /// non-finite values) are never matched; leftOut() says which and why. Results index the
  /// objects of `map` as given.
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
  /// The same, with the camera known to lie in `region` (PoseRegion: within a distance and an
  /// angle of the last pose the host tracked): hypotheses outside it are never generated, so
  /// look-alike objects elsewhere in the map give none, and the search is shorter. nullopt: no
  /// region. An invalid region (non-positive radius, angle outside (0, 180]) is an InvalidInput
  /// status.
  RelocalizationResult relocalize(const std::vector<Observation>& observations, const std::vector<Keypoint>& keypoints,
                                  const std::optional<GravityPrior>& gravity,
                                  const std::optional<PoseRegion>& region) const;

  /// Scores a pose from elsewhere (tracking, odometry, another relocalizer) the way
  /// relocalize() scores its hypotheses: one-to-one matches, their overlaps and the truncated
  /// cost, with Success when it explains scoring.min_inliers observations (fewer if fewer are usable).
  RelocalizationResult scorePose(const std::vector<Observation>& observations, const Pose& pose) const;

  /// Refines a given pose (a motion model's prediction, a reference pose) against the objects
  /// it matches, as relocalize() refines its hypotheses, and scores the result like scorePose.
  /// `refined` says whether refinement moved it.
  RelocalizationResult refineFrom(const std::vector<Observation>& observations, const Pose& start) const;

  /// The ellipse-ellipsoid pairs relocalize() refines a pose on, for `matches` (e.g. a result's
  /// inliers): each observation's ellipse and its object's ellipsoid, with the refinement's
  /// weight for that ellipse (refinement.regular_mask_sigma for a regular mask's fit, else 1).
  /// For a host's own refinePose() call. Throws ellreloc::Error on an index out of range.
  std::vector<EllipseMatch> refinementMatches(const std::vector<Observation>& observations,
                                              const std::vector<ObjectCorrespondence>& matches) const;

  const ObjectMap& map() const { return map_; }
  /// "object ID: WHY" for each object of the map that is never matched.
  const std::vector<std::string>& leftOut() const { return left_out_; }
  const Intrinsics& intrinsics() const { return K_; }
  /// The options in use: `envelope` is the map's camera_envelope when it came from there.
  const RelocalizerOptions& options() const { return options_; }
  /// The up the map's objects tell (estimateMapUp), when the envelope in use was taken from it:
  /// a map without a camera_envelope, RelocalizerOptions::map_envelope and no `envelope` given.
  const std::optional<MapUp>& upFromObjects() const { return up_from_objects_; }

 private:
  // relocalize()'s work on the frame's clock (its time budget and time_ms), with or without the
  // polish of the chosen pose.
  RelocalizationResult relocalizeTimed(const std::vector<Observation>& observations,
                                       const std::vector<Keypoint>& keypoints,
                                       const std::optional<GravityPrior>& gravity,
                                       const std::optional<PoseRegion>& region, bool polish) const;
  // The public calls above hand these the observations in a canonical order (detection score
  // first), so that their results do not depend on the order a detector lists its detections
  // in, and give the results' observation indices back in the order given.
  RelocalizationResult relocalizeInOrder(const std::vector<Observation>& observations,
                                         const std::vector<Keypoint>& keypoints,
                                         const std::optional<GravityPrior>& gravity,
                                         const std::optional<PoseRegion>& region,
                                         std::chrono::steady_clock::time_point start, bool polish) const;
  // relocalize() without the polish (RefinementStageOptions::polish_loss_scale), for a track: it
  // ranks each frame's poses over all of its frames, and a pose polished on one frame fits that
  // frame's agreeing matches more tightly and the other frames worse (docs/pose.md, "Over a track").
  friend class TrackRelocalizer;
  RelocalizationResult relocalizeUnpolished(const std::vector<Observation>& observations,
                                            const std::optional<GravityPrior>& gravity) const;
  RelocalizationResult scorePoseInOrder(const std::vector<Observation>& observations, const Pose& pose) const;
  RelocalizationResult refineFromInOrder(const std::vector<Observation>& observations, const Pose& start) const;

  ObjectMap map_;
  std::optional<MapUp> up_from_objects_;
  std::vector<std::string> left_out_;
  Intrinsics K_;
  RelocalizerOptions options_;
};

}  // namespace ellreloc
