/// \file bind_pose.cpp
/// Relocalization: the options, ObjectRelocalizer (ours and the OA-SLAM preset), its result,
/// the gravity prior, the camera envelope and the Wasserstein refiner on its own. The GIL is
/// released while C++ works, so Python threads can relocalize frames in parallel.

#include <pybind11/stl.h>

#include <atomic>
#include <cmath>
#include <mutex>
#include <thread>

#include "bindings.hpp"
#include "convert.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/pose/track_relocalizer.hpp"
#include "ellreloc/pose/wasserstein_refiner.hpp"

namespace ellreloc::python {
namespace {

/// A relocalizer with the observation policy that turns its frames' detections into ellipses.
struct Relocalizer {
  ObjectRelocalizer relocalizer;
  ObserveOptions observe;
  std::string method;

  std::vector<Observation> observations(const DetectionFrame& frame) const {
    const Intrinsics& K = relocalizer.intrinsics();
    return observeDetections(frame.detections, K.width, K.height, observe);
  }
  /// Keypoints of the raw image in the pinhole image when the frames come through a lens.
  std::vector<Keypoint> keypoints(const std::vector<Keypoint>& raw) const {
    return observe.lens ? undistortKeypoints(*observe.lens, raw) : raw;
  }
};

/// Sets the fields of one option group from a dict: {"min_overlap": 0.2} on options.scoring.
void setGroup(py::object group, const std::string& group_name, const py::handle& values) {
  if (!py::isinstance<py::dict>(values))
    throw py::type_error(group_name + ": expected a dict of field values, got " + describe(values));
  for (const auto& [key, value] : values.cast<py::dict>()) {
    const std::string field = py::str(key);
    if (field.rfind("_", 0) == 0 || !py::hasattr(group, field.c_str()))
      throw py::type_error("unknown option " + group_name + "." + field);
    group.attr(field.c_str()) = value;
  }
}

Relocalizer makeRelocalizer(ObjectMap map, const Intrinsics& K, const std::optional<RelocalizerOptions>& given,
                            const std::string& method, const py::handle& policy, const std::optional<Lens>& lens,
                            const py::kwargs& groups) {
  if (method != "ours" && method != "oa-slam")
    badArgument("method", "expected 'ours' or 'oa-slam', got '" + method + "'");
  if (given && method == "oa-slam") badArgument("method", "give either options or method='oa-slam', not both");
  RelocalizerOptions options = given                 ? *given
                               : method == "oa-slam" ? RelocalizerOptions::oaSlam()
                                                     : RelocalizerOptions{};
  py::object handle = py::cast(&options, py::return_value_policy::reference);
  for (const auto& [key, value] : groups) {
    const std::string name = py::str(key);
    if (name == "envelope") {
      options.envelope = value.is_none() ? std::nullopt : std::optional<CameraEnvelope>(value.cast<CameraEnvelope>());
    } else if (name == "map_envelope") {
      options.map_envelope = value.cast<bool>();
    } else if (name == "search" || name == "scoring" || name == "few_objects" || name == "gravity" ||
               name == "refinement" || name == "acceptance") {
      setGroup(handle.attr(name.c_str()), name, value);
    } else {
      throw py::type_error("unknown option group '" + name +
                           "' (search, scoring, few_objects, gravity, refinement, acceptance, envelope, map_envelope)");
    }
  }
  if (const std::string why = options.validate(); !why.empty()) badArgument("options", why);
  ObserveOptions observe;
  observe.policy = method == "oa-slam" ? ObservationPolicy::Bbox : ObservationPolicy::Solid;
  if (!policy.is_none()) observe.policy = policyFrom(policy);
  if (lens && lens->intrinsics != K) badArgument("lens", "its intrinsics are not the camera's");
  observe.lens = lens;
  return Relocalizer{ObjectRelocalizer(std::move(map), K, options), observe, method};
}

/// Observations from a DetectionFrame (observed with the relocalizer's policy), a list of
/// Detection (likewise) or a list of Observation; a frame also gives its keypoints.
std::vector<Observation> observationsFrom(const Relocalizer& r, const py::handle& h, std::vector<Keypoint>* keypoints) {
  if (py::isinstance<DetectionFrame>(h)) {
    const auto& frame = h.cast<const DetectionFrame&>();
    if (keypoints) *keypoints = r.keypoints(frame.keypoints);
    return r.observations(frame);
  }
  if (py::isinstance<py::str>(h) || !py::hasattr(h, "__iter__"))
    badArgument("frame", "expected a DetectionFrame or a list of Observation or Detection, got " + describe(h));
  std::vector<Observation> out;
  DetectionFrame detections;
  for (const py::handle& item : h) {
    if (py::isinstance<Observation>(item))
      out.push_back(item.cast<Observation>());
    else if (py::isinstance<Detection>(item))
      detections.detections.push_back(item.cast<Detection>());
    else
      badArgument("frame", "expected Observation or Detection items, found " + describe(item));
  }
  if (!out.empty() && !detections.detections.empty()) badArgument("frame", "mixes Observation and Detection items");
  return detections.detections.empty() ? out : r.observations(detections);
}

RelocalizationResult relocalizeOne(const Relocalizer& r, const py::handle& frame, const py::handle& keypoints,
                                   const std::optional<GravityPrior>& gravity,
                                   const std::optional<PoseRegion>& region) {
  std::vector<Keypoint> points;
  const std::vector<Observation> observations = observationsFrom(r, frame, &points);
  if (!keypoints.is_none()) points = r.keypoints(keypointsFrom(keypoints));
  py::gil_scoped_release release;
  return r.relocalizer.relocalize(observations, points, gravity, region);
}

std::vector<RelocalizationResult> relocalizeMany(const Relocalizer& r, const std::vector<DetectionFrame>& frames,
                                                 int threads,
                                                 const std::optional<std::vector<std::optional<PoseRegion>>>& regions) {
  if (threads < 1) badArgument("threads", "must be at least 1");
  if (regions && regions->size() != frames.size())
    badArgument("regions", "expected one PoseRegion or None per frame (" + std::to_string(frames.size()) + "), found " +
                               std::to_string(regions->size()));
  std::vector<RelocalizationResult> results(frames.size());
  py::gil_scoped_release release;
  std::atomic<size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&] {
    try {
      for (size_t i = next++; i < frames.size(); i = next++)
        results[i] = r.relocalizer.relocalize(r.observations(frames[i]), r.keypoints(frames[i].keypoints), std::nullopt,
                                              regions ? (*regions)[i] : std::nullopt);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failure_mutex);
      failure = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min<int>(threads, static_cast<int>(frames.size())); ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  return results;
}

/// A MapUp as a dict (up, t, objects), or None.
py::object mapUpToPython(const std::optional<MapUp>& up) {
  if (!up) return py::none();
  return py::dict(py::arg("up") = toArray(up->up), py::arg("t") = up->t, py::arg("objects") = up->objects);
}

bool hasPose(const RelocalizationResult& r) {
  return r.status == RelocalizationStatus::Success || r.status == RelocalizationStatus::LowEvidence;
}

void bindOptionGroups(py::module_& m) {
  py::enum_<HypothesisSampler>(m, "HypothesisSampler")
      .value("auto", HypothesisSampler::Auto,
             "exhaustive up to search.max_exhaustive_triplets triplets of distinct observations, else prosac")
      .value("exhaustive", HypothesisSampler::Exhaustive, "every triplet of candidate pairs (OA-SLAM)")
      .value("uniform", HypothesisSampler::Uniform)
      .value("prosac", HypothesisSampler::Prosac, "random triplets, best (score x size) first");
  py::enum_<OverlapMeasure>(m, "OverlapMeasure")
      .value("ellipse_iou", OverlapMeasure::EllipseIoU)
      .value("box_iou", OverlapMeasure::BoxIoU, "observed box vs the projection's bounding box (OA-SLAM)");
  py::enum_<RobustLoss>(m, "RobustLoss")
      .value("none", RobustLoss::None)
      .value("huber", RobustLoss::Huber)
      .value("cauchy", RobustLoss::Cauchy);
  py::enum_<RefinerBackend>(m, "RefinerBackend")
      .value("levenberg_marquardt", RefinerBackend::LevenbergMarquardt)
      .value("ceres", RefinerBackend::Ceres);

  py::class_<RansacOptions>(m, "SearchBudget", "Sample and hypothesis budgets, adaptive stopping and the seed.")
      .def(py::init<>())
      .def_readwrite("min_iterations", &RansacOptions::min_iterations)
      .def_readwrite("max_iterations", &RansacOptions::max_iterations)
      .def_readwrite("max_hypotheses", &RansacOptions::max_hypotheses)
      .def_readwrite("max_time_ms", &RansacOptions::max_time_ms, "wall-clock budget per frame; 0 = none")
      .def_readwrite("success_probability", &RansacOptions::success_probability)
      .def_readwrite("enough_extension", &RansacOptions::enough_extension,
                     "after a pose explaining every observation (search.stop_when_explained): this many times the "
                     "samples drawn so far, then stop")
      .def_readwrite("skip_repeated_samples", &RansacOptions::skip_repeated_samples,
                     "a triplet drawn before counts as drawn but is not solved and scored again")
      .def_readwrite("seed", &RansacOptions::seed);
  py::class_<SearchOptions>(m, "SearchOptions")
      .def(py::init<>())
      .def_readwrite("sampler", &SearchOptions::sampler)
      .def_readwrite("max_exhaustive_triplets", &SearchOptions::max_exhaustive_triplets)
      .def_readwrite("correct_centres", &SearchOptions::correct_centres)
      .def_readwrite("uncorrected_when_closer", &SearchOptions::uncorrected_when_closer)
      .def_readwrite("check_sample_overlap", &SearchOptions::check_sample_overlap)
      .def_readwrite("stop_when_explained", &SearchOptions::stop_when_explained,
                     "end a sampled search once a pose explains every usable observation (at least four) well")
      .def_readwrite("explained_mean_credit", &SearchOptions::explained_mean_credit,
                     "the mean credit (overlap) such a pose needs")
      .def_readwrite("refine_explained", &SearchOptions::refine_explained,
                     "refine a hypothesis that explains every usable observation (at least four) loosely, when scored")
      .def_readwrite("budget", &SearchOptions::budget)
      .def_readwrite("max_overlap_evaluations", &SearchOptions::max_overlap_evaluations)
      .def_readwrite("max_candidate_pairs", &SearchOptions::max_candidate_pairs)
      .def_readwrite("threads", &SearchOptions::threads, "threads splitting one frame's hypotheses (same result)");
  py::class_<ScoringOptions>(m, "ScoringOptions")
      .def(py::init<>())
      .def_readwrite("overlap", &ScoringOptions::overlap)
      .def_readwrite("min_overlap", &ScoringOptions::min_overlap)
      .def_readwrite("unmatched_cost", &ScoringOptions::unmatched_cost)
      .def_readwrite("min_category_share", &ScoringOptions::min_category_share)
      .def_readwrite("weigh_minority_labels", &ScoringOptions::weigh_minority_labels)
      .def_readwrite("min_inliers", &ScoringOptions::min_inliers);
  py::class_<RefinerOptions>(m, "RefinerOptions")
      .def(py::init<>())
      .def_readwrite("backend", &RefinerOptions::backend)
      .def_readwrite("object_loss", &RefinerOptions::object_loss)
      .def_readwrite("object_loss_scale", &RefinerOptions::object_loss_scale)
      .def_readwrite("point_loss", &RefinerOptions::point_loss)
      .def_readwrite("point_sigma_px", &RefinerOptions::point_sigma_px)
      .def_readwrite("point_loss_scale", &RefinerOptions::point_loss_scale)
      .def_readwrite("point_weight", &RefinerOptions::point_weight)
      .def_readwrite("max_iterations", &RefinerOptions::max_iterations)
      .def_readwrite("function_tolerance", &RefinerOptions::function_tolerance);
  py::class_<FewObjectOptions>(m, "FewObjectSolverOptions")
      .def(py::init<>())
      .def_readwrite("angle_steps", &FewObjectOptions::angle_steps)
      .def_readwrite("axis_step_deg", &FewObjectOptions::axis_step_deg)
      .def_readwrite("max_poses", &FewObjectOptions::max_poses)
      .def_readwrite("skip_tilted", &FewObjectOptions::skip_tilted)
      .def_readwrite("refiner", &FewObjectOptions::refiner);
  py::class_<FewObjectSearchOptions>(m, "FewObjectOptions")
      .def(py::init<>())
      .def_readwrite("enabled", &FewObjectSearchOptions::enabled)
      .def_readwrite("max_observations", &FewObjectSearchOptions::max_observations)
      .def_readwrite("max_pair_hypotheses", &FewObjectSearchOptions::max_pair_hypotheses)
      .def_readwrite("solver", &FewObjectSearchOptions::solver);
  py::class_<GravityOptions>(m, "GravityOptions")
      .def(py::init<>())
      .def_readwrite("gate_deg", &GravityOptions::gate_deg)
      .def_readwrite("in_every_refinement", &GravityOptions::in_every_refinement);
  py::class_<RefinementStageOptions>(m, "RefinementOptions")
      .def(py::init<>())
      .def_readwrite("enabled", &RefinementStageOptions::enabled)
      .def_readwrite("top_k", &RefinementStageOptions::top_k)
      .def_readwrite("cost_margin", &RefinementStageOptions::cost_margin)
      .def_readwrite("rounds", &RefinementStageOptions::rounds)
      .def_readwrite("regular_mask_sigma", &RefinementStageOptions::regular_mask_sigma)
      .def_readwrite("polish_loss_scale", &RefinementStageOptions::polish_loss_scale)
      .def_readwrite("refiner", &RefinementStageOptions::refiner);
  py::class_<AcceptanceOptions>(m, "AcceptanceOptions")
      .def(py::init<>())
      .def_readwrite("enabled", &AcceptanceOptions::enabled)
      .def_readwrite("min_evidence", &AcceptanceOptions::min_evidence)
      .def_readwrite("unexplained_penalty", &AcceptanceOptions::unexplained_penalty)
      .def_readwrite("min_margin", &AcceptanceOptions::min_margin);
}

void bindPriors(py::module_& m) {
  py::class_<GravityPrior>(m, "GravityPrior", "The up direction in the camera (an IMU) and in the map.")
      .def(py::init([](const py::handle& up_in_camera, const py::handle& up_in_map, double sigma_deg) {
             GravityPrior g;
             g.up_in_camera = vector<3>(up_in_camera, "up_in_camera");
             g.up_in_map = vector<3>(up_in_map, "up_in_map");
             g.sigma_deg = sigma_deg;
             if (!g.isValid()) badArgument("GravityPrior", "directions must be non-zero and sigma_deg positive");
             return g;
           }),
           py::arg("up_in_camera"), py::arg("up_in_map") = toArray(Eigen::Vector3d::UnitZ()),
           py::arg("sigma_deg") = 2.0)
      .def_static(
          "at_pose",
          [](const Pose& pose, const py::handle& up, double sigma_deg) {
            return GravityPrior::atPose(pose, vector<3>(up, "up_in_map"), sigma_deg);
          },
          py::arg("pose"), py::arg("up_in_map") = toArray(Eigen::Vector3d::UnitZ()), py::arg("sigma_deg") = 2.0,
          "The prior an IMU would give at a known pose.")
      .def_property_readonly("up_in_camera", [](const GravityPrior& g) { return toArray(g.up_in_camera); })
      .def_property_readonly("up_in_map", [](const GravityPrior& g) { return toArray(g.up_in_map); })
      .def_readonly("sigma_deg", &GravityPrior::sigma_deg)
      .def("error_deg", &GravityPrior::errorDeg, py::arg("pose"));

  py::class_<PoseRegion>(m, "PoseRegion",
                         "Where the camera is known to be: within radius_m and max_rotation_deg of `pose` (the last "
                         "pose the host tracked, world->camera).")
      .def(py::init([](const Pose& pose, double radius_m, double max_rotation_deg) {
             const PoseRegion r{pose, radius_m, max_rotation_deg};
             if (!r.isValid())
               badArgument("PoseRegion", "expected a valid pose, a positive radius_m and max_rotation_deg in (0, 180]");
             return r;
           }),
           py::arg("pose"), py::arg("radius_m") = PoseRegion().radius_m,
           py::arg("max_rotation_deg") = PoseRegion().max_rotation_deg)
      .def_readonly("pose", &PoseRegion::pose)
      .def_readonly("radius_m", &PoseRegion::radius_m)
      .def_readonly("max_rotation_deg", &PoseRegion::max_rotation_deg)
      .def("admits", &PoseRegion::admits, py::arg("pose"), "Whether a world->camera pose lies in the region.");

  py::class_<CameraEnvelope>(m, "CameraEnvelope", "Where the camera can be: heights along `up` and tilts.")
      .def_static(
          "from_keyframes",
          [](const std::vector<Pose>& keyframes, const py::handle& up, double height_margin, double tilt_margin_deg) {
            std::optional<Eigen::Vector3d> u;
            if (!up.is_none()) u = vector<3>(up, "up");
            auto e = CameraEnvelope::fromKeyframes(keyframes, u, height_margin, tilt_margin_deg);
            if (!e) badArgument("keyframes", "need at least 2 valid poses (and a non-zero up)");
            return *e;
          },
          py::arg("keyframes"), py::arg("up") = py::none(), py::arg("height_margin") = 0.5,
          py::arg("tilt_margin_deg") = 20.0, "The envelope of mapping keyframes, widened by the margins.")
      .def_static(
          "upright",
          [](const py::handle& up, double max_tilt_deg, double max_roll_deg) {
            auto e = CameraEnvelope::upright(vector<3>(up, "up"), max_tilt_deg, max_roll_deg);
            if (!e)
              badArgument("upright",
                          "needs a finite, non-zero up, max_tilt_deg in (0, 180] and max_roll_deg in (0, 90]");
            return *e;
          },
          py::arg("up"), py::arg("max_tilt_deg") = 90.0, py::arg("max_roll_deg") = 90.0,
          "A camera at any height whose image-up stays within max_tilt_deg of `up` (90: never upside down) and "
          "whose image rows stay within max_roll_deg of level (90: any roll; needs `up` near the vertical).")
      .def_property_readonly("up", [](const CameraEnvelope& e) { return toArray(e.up); })
      .def_readonly("min_height", &CameraEnvelope::min_height)
      .def_readonly("max_height", &CameraEnvelope::max_height)
      .def_readonly("min_tilt_deg", &CameraEnvelope::min_tilt_deg)
      .def_readonly("max_tilt_deg", &CameraEnvelope::max_tilt_deg)
      .def_readonly("max_roll_deg", &CameraEnvelope::max_roll_deg)
      .def("admits", &CameraEnvelope::admits, py::arg("pose"));
}

void bindRelocalizerOptions(py::module_& m) {
  bindOptionGroups(m);
  bindPriors(m);
  py::class_<RelocalizerOptions>(m, "RelocalizerOptions",
                                 "Options in groups, one per stage (docs/pose.md). Nested fields are writable: "
                                 "options.scoring.min_overlap = 0.2.")
      .def(py::init<>())
      .def_static("oa_slam", &RelocalizerOptions::oaSlam, "OA-SLAM's exhaustive relocalization (the baseline).")
      .def_readwrite("search", &RelocalizerOptions::search)
      .def_readwrite("scoring", &RelocalizerOptions::scoring)
      .def_readwrite("few_objects", &RelocalizerOptions::few_objects)
      .def_readwrite("gravity", &RelocalizerOptions::gravity)
      .def_readwrite("refinement", &RelocalizerOptions::refinement)
      .def_readwrite("acceptance", &RelocalizerOptions::acceptance)
      .def_readwrite("envelope", &RelocalizerOptions::envelope,
                     "Where the camera can be (CameraEnvelope); None: the map's camera_envelope when map_envelope and "
                     "the map has one, else anywhere.")
      .def_readwrite("map_envelope", &RelocalizerOptions::map_envelope,
                     "Without `envelope`, keep the camera within the map's camera_envelope when it has one.")
      .def("validate", &RelocalizerOptions::validate, "'' when every field is in range, else the first that is not.");
}

void bindResult(py::module_& m) {
  py::enum_<RelocalizationStatus>(m, "RelocalizationStatus")
      .value("success", RelocalizationStatus::Success)
      .value("not_enough_observations", RelocalizationStatus::NotEnoughObservations)
      .value("no_consistent_hypothesis", RelocalizationStatus::NoConsistentHypothesis)
      .value("invalid_input", RelocalizationStatus::InvalidInput)
      .value("low_evidence", RelocalizationStatus::LowEvidence,
             "a pose was found, but the observations support it too weakly");
  py::class_<ObjectCorrespondence>(m, "Match", "An observation matched to a map object at the returned pose.")
      .def_readonly("observation", &ObjectCorrespondence::observation, "index into the observations")
      .def_readonly("object", &ObjectCorrespondence::object, "index into the relocalizer's map.objects")
      .def_readonly("overlap", &ObjectCorrespondence::overlap)
      .def_readonly("credit", &ObjectCorrespondence::credit)
      .def("__repr__", [](const ObjectCorrespondence& c) {
        return "Match(observation=" + std::to_string(c.observation) + ", object=" + std::to_string(c.object) +
               ", overlap=" + std::to_string(c.overlap) + ")";
      });
  py::class_<RelocalizationResult>(m, "RelocalizationResult")
      .def_readonly("status", &RelocalizationResult::status)
      .def_readonly("reason", &RelocalizationResult::reason)
      .def_property_readonly("success",
                             [](const RelocalizationResult& r) { return r.status == RelocalizationStatus::Success; })
      .def_property_readonly(
          "pose", [](const RelocalizationResult& r) { return hasPose(r) ? std::optional<Pose>(r.pose) : std::nullopt; },
          "The world->camera pose (also kept for low_evidence), else None.")
      .def_property_readonly(
          "T_wc",
          [](const RelocalizationResult& r) -> py::object {
            if (!hasPose(r)) return py::none();
            return py::cast(r.pose).attr("T_wc");
          },
          "The camera->world 4x4 matrix, or None.")
      .def_readonly("matches", &RelocalizationResult::inliers)
      .def_readonly("score", &RelocalizationResult::evidence,
                    "The evidence: sum of the matches' overlaps minus a penalty per unexplained observation "
                    "(higher is better; the acceptance test compares it with acceptance.min_evidence).")
      .def_readonly("cost", &RelocalizationResult::cost, "Truncated overlap cost (lower is better).")
      .def_readonly("margin", &RelocalizationResult::margin,
                    "How much higher the cost of the best rival pose (30 cm or 30 degrees away) is: near 0 when the "
                    "frame fits two poses alike, inf when no refined hypothesis disagreed "
                    "(acceptance.min_margin).")
      .def_property_readonly(
          "rival", [](const RelocalizationResult& r) { return hasPose(r) ? r.rival : std::nullopt; },
          "The best refined pose that is another answer (30 cm or 30 degrees away; world->camera), whose cost is "
          "`margin` higher, or None: a host that checks poses with its points can try it when `pose` fails.")
      .def_property_readonly(
          "alternatives",
          [](const RelocalizationResult& r) {
            std::vector<std::pair<Pose, double>> out;
            if (hasPose(r))
              for (const ScoredPose& a : r.alternatives) out.emplace_back(a.pose, a.cost);
            return out;
          },
          "Every other answer among the refined hypotheses as (pose, cost), cheapest first, each 30 cm or 30 "
          "degrees away from `pose` and from every cheaper one (the first is `rival`): the poses to check in turn "
          "when `pose` fails.")
      .def_readonly("mean_overlap", &RelocalizationResult::mean_overlap)
      .def_readonly("skipped", &RelocalizationResult::skipped, "(observation index, reason) of observations not used")
      .def_readonly("hypotheses", &RelocalizationResult::hypotheses)
      .def_readonly("iterations", &RelocalizationResult::iterations)
      .def_readonly("few_object_hypotheses", &RelocalizationResult::few_object_hypotheses)
      .def_readonly("budget_exhausted", &RelocalizationResult::budget_exhausted)
      .def_readonly("refined", &RelocalizationResult::refined)
      .def_readonly("time_ms", &RelocalizationResult::time_ms)
      .def("__repr__", [](const RelocalizationResult& r) {
        return std::string("RelocalizationResult(") + py::str(py::cast(r.status)).cast<std::string>() + ", " +
               std::to_string(r.inliers.size()) + " matches, " + r.reason + ")";
      });
}

void bindRelocalizer(py::module_& m) {
  py::class_<Relocalizer>(
      m, "ObjectRelocalizer",
      "Relocalizes query frames against a map of ellipsoids. Keyword groups set options: "
      "ObjectRelocalizer(map, camera, scoring={'min_overlap': 0.2}, acceptance={'enabled': False}). "
      "method='oa-slam' gives OA-SLAM's exhaustive baseline (with the 'bbox' policy). lens=read_lens(path): "
      "the frames' detections and keypoints are of the raw images of that distorted lens.")
      .def(py::init(&makeRelocalizer), py::arg("map"), py::arg("camera"), py::arg("options") = py::none(),
           py::arg("method") = "ours", py::arg("policy") = py::none(), py::arg("lens") = py::none())
      .def("relocalize", &relocalizeOne, py::arg("frame"), py::arg("keypoints") = py::none(),
           py::arg("gravity") = py::none(), py::arg("region") = py::none(),
           "Relocalizes one frame: a DetectionFrame (observed with this relocalizer's policy, its keypoints used "
           "unless `keypoints` is given), a list of Detection or a list of Observation. `keypoints`: Keypoint "
           "items or an (n, 3) array of (point_index, u, v); `gravity`: a GravityPrior; `region`: a PoseRegion "
           "(poses outside it are never hypotheses). The GIL is released meanwhile.")
      .def("relocalize_frames", &relocalizeMany, py::arg("frames"), py::arg("threads") = 1,
           py::arg("regions") = py::none(),
           "Relocalizes many DetectionFrames in C++ on `threads` threads; the same results as relocalize() on each "
           "(with `regions`, one PoseRegion or None per frame, as its `region`).")
      .def(
          "observe", [](const Relocalizer& r, const py::handle& frame) { return observationsFrom(r, frame, nullptr); },
          py::arg("frame"), "The observations relocalize() makes of a frame.")
      .def(
          "score_pose",
          [](const Relocalizer& r, const py::handle& frame, const Pose& pose) {
            const std::vector<Observation> obs = observationsFrom(r, frame, nullptr);
            py::gil_scoped_release release;
            return r.relocalizer.scorePose(obs, pose);
          },
          py::arg("frame"), py::arg("pose"), "Scores a pose from elsewhere the way relocalize() scores its hypotheses.")
      .def(
          "refine_from",
          [](const Relocalizer& r, const py::handle& frame, const Pose& start) {
            const std::vector<Observation> obs = observationsFrom(r, frame, nullptr);
            py::gil_scoped_release release;
            return r.relocalizer.refineFrom(obs, start);
          },
          py::arg("frame"), py::arg("start"), "Refines a given pose against the objects it matches, then scores it.")
      .def(
          "refinement_matches",
          [](const Relocalizer& r, const py::handle& frame, const std::vector<ObjectCorrespondence>& matches) {
            const std::vector<Observation> obs = observationsFrom(r, frame, nullptr);
            return r.relocalizer.refinementMatches(obs, matches);
          },
          py::arg("frame"), py::arg("matches"),
          "The EllipseMatch pairs relocalize() refines on for these matches (e.g. a result's inliers), each weighed "
          "as the refinement weighs it; for refine_pose().")
      .def_property_readonly("map", [](const Relocalizer& r) { return r.relocalizer.map(); })
      .def_property_readonly("camera", [](const Relocalizer& r) { return r.relocalizer.intrinsics(); })
      .def_property_readonly(
          "options", [](const Relocalizer& r) { return r.relocalizer.options(); }, "A copy.")
      .def_property_readonly("policy", [](const Relocalizer& r) { return r.observe.policy; })
      .def_property_readonly("lens", [](const Relocalizer& r) { return r.observe.lens; })
      .def_property_readonly("method", [](const Relocalizer& r) { return r.method; })
      .def_property_readonly(
          "left_out", [](const Relocalizer& r) { return r.relocalizer.leftOut(); },
          "'object ID: why' for each map object that is never matched.")
      .def_property_readonly(
          "up_from_objects", [](const Relocalizer& r) { return mapUpToPython(r.relocalizer.upFromObjects()); },
          "The map's up its objects tell (as estimate_map_up) when the camera is kept upright about it: a map "
          "without a camera_envelope, map_envelope on and no envelope given; else None.");
  m.def(
      "estimate_map_up", [](const ObjectMap& map, double min_t) { return mapUpToPython(estimateMapUp(map, min_t)); },
      py::arg("map"), py::arg("min_t") = 2.5,
      "Which way is up in a map from its objects alone: the direction of least spread of their centres, signed "
      "by the usual heights of their categories; a dict (up, t, objects) when the evidence is clear, else None.");
}

/// A TrackRelocalizer with the Python relocalizer it reads (kept alive) and observes frames with.
struct Track {
  py::object owner;
  const Relocalizer* relocalizer;
  std::unique_ptr<TrackRelocalizer> track;
};

void bindTrack(py::module_& m) {
  py::class_<TrackResult>(m, "TrackResult", "What TrackRelocalizer.add() found for the newest frame.")
      .def_readonly("result", &TrackResult::result,
                    "The newest frame's RelocalizationResult: the track's best pose refined on this frame; its "
                    "matches, cost and score are this frame's, margin, rival and alternatives compare track costs.")
      .def_readonly("track_cost", &TrackResult::track_cost,
                    "The sum over the track's frames of their cost at the pose.")
      .def_readonly("track_evidence", &TrackResult::track_evidence,
                    "The sum over the track's frames of their evidence at the pose (the acceptance test reads it).")
      .def_readonly("track_matches", &TrackResult::track_matches, "Observations explained over the track's frames.")
      .def_readonly("frames", &TrackResult::frames,
                    "Frames whose observations ranked the poses, this one included (only this one while an unknown "
                    "odometry scale has no estimate).")
      .def_readonly("candidates", &TrackResult::candidates, "Distinct poses ranked.")
      .def_readonly("found_by", &TrackResult::found_by,
                    "Whose search found the pose: 0 this frame, 1 the one before, ...; -1 when none did.")
      .def_readonly("scale", &TrackResult::scale,
                    "Map units per odometry unit the poses were carried with (map metres in a metric map): 1 / the "
                    "map's unit_metres with metric odometry, else the estimate (0 while there is none).")
      .def("__repr__", [](const TrackResult& t) {
        return std::string("TrackResult(") + py::str(py::cast(t.result.status)).cast<std::string>() + ", " +
               std::to_string(t.frames) + " frames, found by " + std::to_string(t.found_by) + ")";
      });
  py::class_<Track>(m, "TrackRelocalizer",
                    "Relocalizes each new frame of a track a host follows without the map (its odometry gives each "
                    "frame's pose): every frame's poses, carried to the newest frame, ranked over the whole track "
                    "(docs/pose.md, 'Over a track').")
      .def(py::init([](py::object relocalizer, int max_frames, double min_mean_evidence, double min_margin,
                       bool metric_odometry) {
             TrackOptions options;
             options.max_frames = max_frames;
             options.metric_odometry = metric_odometry;
             options.min_mean_evidence = min_mean_evidence;
             options.min_margin = min_margin;
             if (const std::string why = options.validate(); !why.empty()) badArgument("TrackRelocalizer", why);
             const auto* r = relocalizer.cast<const Relocalizer*>();
             return Track{relocalizer, r, std::make_unique<TrackRelocalizer>(r->relocalizer, options)};
           }),
           py::arg("relocalizer"), py::arg("max_frames") = TrackOptions().max_frames,
           py::arg("min_mean_evidence") = TrackOptions().min_mean_evidence,
           py::arg("min_margin") = TrackOptions().min_margin,
           py::arg("metric_odometry") = TrackOptions().metric_odometry,
           "metric_odometry=False for a monocular host's odometry, whose scale is unknown: the track estimates it "
           "(TrackResult.scale).")
      .def(
          "add",
          [](Track& t, const py::handle& frame, const Pose& odometry_pose, const std::optional<GravityPrior>& gravity) {
            const std::vector<Observation> obs = observationsFrom(*t.relocalizer, frame, nullptr);
            py::gil_scoped_release release;
            return t.track->add(obs, odometry_pose, gravity);
          },
          py::arg("frame"), py::arg("odometry_pose"), py::arg("gravity") = py::none(),
          "Adds a frame (a DetectionFrame, or a list of Detection or Observation) with its camera pose in the "
          "odometry's frame (world->camera; metric unless metric_odometry=False) and relocalizes it with the "
          "track's help; an invalid pose leaves the track unchanged (status invalid_input).")
      .def(
          "reset", [](Track& t) { t.track->reset(); }, "Forgets every frame (the odometry restarted).")
      .def("__len__", [](const Track& t) { return t.track->size(); });
}

void bindRefiner(py::module_& m) {
  py::class_<EllipseMatch>(m, "EllipseMatch",
                           "An observed ellipse and the map ellipsoid it shows; sigma is the ellipse's expected "
                           "error in units of its size (1: a box's ellipse), a smaller one weighs more.")
      .def(py::init([](const Ellipse& e, const Ellipsoid& q, double sigma) {
             if (!(std::isfinite(sigma) && sigma > 0))
               throw ellreloc::Error("EllipseMatch: sigma must be a positive number");
             return EllipseMatch{e, q, sigma};
           }),
           py::arg("observed"), py::arg("ellipsoid"), py::arg("sigma") = 1.0)
      .def_readwrite("observed", &EllipseMatch::observed)
      .def_readwrite("ellipsoid", &EllipseMatch::ellipsoid)
      .def_readwrite("sigma", &EllipseMatch::sigma);
  py::class_<RefinementResult>(m, "RefinementResult")
      .def_readonly("pose", &RefinementResult::pose)
      .def_readonly("initial_cost", &RefinementResult::initial_cost)
      .def_readonly("final_cost", &RefinementResult::final_cost)
      .def_readonly("iterations", &RefinementResult::iterations)
      .def_readonly("converged", &RefinementResult::converged)
      .def_readonly("fell_back", &RefinementResult::fell_back)
      .def_readonly("message", &RefinementResult::message)
      .def_readonly("object_residuals", &RefinementResult::object_residuals)
      .def_readonly("point_residuals", &RefinementResult::point_residuals);
  m.def(
      "refine_pose",
      [](const Intrinsics& K, const Pose& initial, const py::handle& matches, const py::handle& points_2d,
         const py::handle& points_3d, const std::optional<RefinerOptions>& options,
         const std::optional<GravityPrior>& gravity) {
        std::vector<EllipseMatch> objects;
        for (const py::handle& item : matches) {
          if (py::isinstance<EllipseMatch>(item))
            objects.push_back(item.cast<EllipseMatch>());
          else if (py::isinstance<py::tuple>(item) && py::len(item) == 2)
            objects.push_back({item.cast<py::tuple>()[0].cast<Ellipse>(), item.cast<py::tuple>()[1].cast<Ellipsoid>()});
          else
            badArgument("matches", "expected EllipseMatch or (Ellipse, Ellipsoid) items, found " + describe(item));
        }
        std::vector<PointMatch> points;
        if (!points_2d.is_none() || !points_3d.is_none()) {
          if (points_2d.is_none() || points_3d.is_none()) badArgument("points_2d, points_3d", "give both or neither");
          const auto uv = rows<2>(points_2d, "points_2d");
          const auto X = rows<3>(points_3d, "points_3d");
          if (uv.size() != X.size()) badArgument("points_2d, points_3d", "have different lengths");
          for (size_t i = 0; i < uv.size(); ++i) points.push_back({uv[i], X[i]});
        }
        py::gil_scoped_release release;
        return refinePose(K, initial, objects, points, options.value_or(RefinerOptions{}), gravity);
      },
      py::arg("camera"), py::arg("initial"), py::arg("matches"), py::arg("points_2d") = py::none(),
      py::arg("points_3d") = py::none(), py::arg("options") = py::none(), py::arg("gravity") = py::none(),
      "The Wasserstein refinement (paper eq. 8) of a world->camera pose from ellipse-ellipsoid matches, "
      "optionally with 2D-3D point matches and a gravity prior. Never returns a pose of higher cost.");
}

}  // namespace

void bindPose(py::module_& m) {
  bindRelocalizerOptions(m);
  bindResult(m);
  bindRelocalizer(m);
  bindTrack(m);
  bindRefiner(m);
}

}  // namespace ellreloc::python
