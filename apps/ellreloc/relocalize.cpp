// `ellreloc relocalize`.

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "commands.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/overlay.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/pose/track_relocalizer.hpp"

namespace ellreloc::cli {

namespace {

/// The options of what a host knows beyond the frame: gravity, the map's up and the camera's
/// envelope, and where the camera was last tracked.
void addPriorOptions(CLI::App* r, RelocalizeArgs& a) {
  auto* camera_up = r->add_option("--camera-up", a.camera_up,
                                  "gravity prior: the up direction in the camera frame (x right, y down, z forward), "
                                  "for a camera at a fixed tilt, e.g. 0,-1,0 for a level camera")
                        ->expected(3)
                        ->delimiter(',');
  auto* map_up =
      r->add_option(
           "--map-up", a.map_up,
           "the up direction in the map frame, e.g. 0,0,1: with --camera-up a gravity prior; the up of --envelope "
           "and of --max-tilt")
          ->expected(3)
          ->delimiter(',');
  camera_up->needs(map_up);
  auto* max_tilt =
      r->add_option("--max-tilt", a.max_tilt_deg,
                    "with --map-up and no mapping poses: the camera's image-up stays within this many degrees of the "
                    "map's up, at any height (90: never upside down); replaces the map's camera_envelope")
          ->check(CLI::Range(0.0, 180.0))
          ->needs(map_up)
          ->excludes("--envelope")
          ->excludes("--no-map-envelope");
  r->add_option("--max-roll", a.max_roll_deg,
                "with --max-tilt: the camera's image rows stay within this many degrees of level (90: any roll; "
                "give an up near the vertical: about a tilted up even a level camera rolls as it turns)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 90.0))
      ->needs(max_tilt);
  r->add_option("--gravity-sigma", a.gravity_sigma_deg, "accuracy of the gravity prior in degrees")
      ->capture_default_str()
      ->needs(camera_up);
  auto* near = r->add_option("--near", a.near,
                             "TUM poses (camera->world) where the camera was last tracked: each frame is searched "
                             "only near the latest one at or before its timestamp (--near-radius, --near-angle); "
                             "frames before the first are searched everywhere")
                   ->check(CLI::ExistingFile);
  r->add_option("--near-radius", a.near_radius_m, "with --near: how far the camera can have moved, in metres")
      ->capture_default_str()
      ->needs(near);
  r->add_option("--near-angle", a.near_angle_deg,
                "with --near: how far the camera can have turned, in degrees (180: any way)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 180.0))
      ->needs(near);
  auto* track = r->add_option("--track", a.track,
                              "TUM poses from your own odometry (camera->world in its frame, metric unless "
                              "--track-scale-unknown): the frames are "
                              "relocalized in timestamp order as one track, on one thread, each with the help of the "
                              "frames before it (--track-frames in all); a frame without a pose within 20 ms starts "
                              "the track again")
                    ->check(CLI::ExistingFile)
                    ->excludes(near);
  r->add_option("--track-frames", a.track_frames, "with --track: the newest frames kept in the track")
      ->capture_default_str()
      ->check(CLI::Range(1, 100))
      ->needs(track);
  r->add_flag("--track-scale-unknown", a.track_scale_unknown,
              "with --track: the odometry's scale is unknown (a monocular SLAM map's); the track estimates it and the "
              "report gives it as track.scale")
      ->needs(track);
}

}  // namespace

CLI::App* addRelocalizeCommand(CLI::App& app, RelocalizeArgs& a) {
  CLI::App* r = app.add_subcommand("relocalize", "recover the camera pose of each frame from its detections");
  r->add_option("--camera", a.camera, "camera intrinsics: ORB-SLAM YAML or JSON")->required()->check(CLI::ExistingFile);
  r->add_option("--map", a.map, "map JSON or OA-SLAM text map")->required()->check(CLI::ExistingFile);
  r->add_option("--detections", a.detections, "detections JSON: the query frames (docs/formats.md)")
      ->required()
      ->check(CLI::ExistingFile);
  r->add_option("--method", a.method, "ours or oa-slam (the OA-SLAM baseline)")->capture_default_str();
  r->add_option("--policy", a.policy, "observation policy (default: solid for ours, bbox for oa-slam)");
  r->add_option("--out", a.out, "TUM poses of the relocalized frames")->required();
  r->add_option("--report", a.report,
                "per-frame JSON report: status, matches, score, margin, the other answers found (alternatives), time");
  r->add_option("--reference", a.reference,
                "TUM poses to diagnose against (the ground truth, or another method's output): the report gives "
                "each frame's reference pose score under our cost and, for a pose off by >= 30 cm or 30 deg, "
                "whether the search missed a better pose or the score preferred a wrong one")
      ->check(CLI::ExistingFile);
  r->add_option("--envelope", a.envelope,
                "TUM trajectory of the mapping keyframes: poses outside their heights and tilts (+-0.5 m, +-20 deg; "
                "up from --map-up, else the keyframes' mean image-up) are never hypotheses; without it, the "
                "map's own camera_envelope (maps built by ellreloc map record one) keeps the camera where the map "
                "was made")
      ->check(CLI::ExistingFile);
  auto* no_map_envelope = r->add_flag("--no-map-envelope", a.no_map_envelope,
                                      "ignore the map's camera_envelope: poses anywhere (the oa-slam method always "
                                      "does)");
  r->add_option("--points", a.points,
                "refine with keypoints matched to the map's points: from this file (same frame "
                "layout), or from the detections file when no file is given")
      ->expected(0, 1);
  r->add_option("--overlays", a.overlays,
                "folder for one PNG per frame (TIMESTAMP.png): detections, the map projected with the returned pose "
                "and the matches, the map at the --reference pose too, over the frame's image when its file_name "
                "resolves next to the detections file");
  r->add_option("--threads", a.threads, "frames in parallel")->capture_default_str()->check(CLI::Range(1, 256));
  r->add_option("--max-time-ms", a.max_time_ms,
                "wall-clock budget of each frame's hypothesis search in ms (0: none; results then depend on the "
                "machine)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e9));
  r->add_option("--min-evidence", a.min_evidence,
                "report a pose only when its matches' overlaps, less 0.5 per observation left unexplained, sum to "
                "this (ours; frames of random boxes pass 1% of the time at the default)")
      ->capture_default_str()
      ->check(CLI::Range(-1e6, 1e6));
  auto* min_margin =
      r->add_option("--min-margin", a.min_margin,
                    "report a pose only when the best other pose found (30 cm or 30 deg away) costs at least this much "
                    "more (ours; 0.1-0.3 drop many wrong poses and a few valid ones: docs/reliability.md)")
          ->capture_default_str()
          ->check(CLI::Range(0.0, 1e6));
  r->add_flag("--undistort", a.undistort,
              "the detections were made on raw images of a distorted lens: undistort their boxes, ellipses and "
              "keypoints with the --camera file's Camera.k1, k2, p1, p2, k3 (left out: 0) before relocalizing");
  r->add_flag("--accept-all", a.accept_all,
              "report every pose found, however weakly supported (as the oa-slam method does)")
      ->excludes(min_margin);
  addPriorOptions(r, a);
  r->footer(
      "Example: ellreloc relocalize --camera camera.yaml --map map.json --detections keyframes.detections.json "
      "--method ours --out poses.txt --report report.json --threads 2");
  return r;
}

namespace {

/// A reference pose under our cost: as given, and refined as our hypotheses are.
struct ReferenceScore {
  RelocalizationResult given, refined;
};

/// The score of a frame's reference pose, as given and refined.
ReferenceScore scoreReference(const ObjectRelocalizer& relocalizer, const std::vector<Observation>& observations,
                              const Pose& reference) {
  return {relocalizer.scorePose(observations, reference), relocalizer.refineFrom(observations, reference)};
}

/// --track: the frames in timestamp order as one track (TrackRelocalizer), on this thread; a
/// frame without an odometry pose is relocalized alone and starts the track again. Fills what
/// relocalizeFrames does, and `tracks` with each tracked frame's track result.
std::vector<RelocalizationResult> relocalizeAlongTrack(
    const ObjectRelocalizer& relocalizer, const std::vector<DetectionFrame>& frames,
    const std::vector<double>& timestamps, const std::vector<std::optional<Pose>>& odometry,
    const TrackOptions& track_options, const std::optional<GravityPrior>& gravity,
    const ObserveOptions& observe_options, const std::vector<std::optional<Pose>>& references,
    std::vector<std::vector<Observation>>* observations_out, std::vector<ReferenceScore>* reference_scores,
    std::vector<std::optional<TrackResult>>* tracks) {
  std::vector<size_t> order(frames.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return timestamps[x] < timestamps[y]; });
  std::vector<RelocalizationResult> results(frames.size());
  const Intrinsics& K = relocalizer.intrinsics();
  TrackRelocalizer track(relocalizer, track_options);
  for (const size_t i : order) {
    const std::vector<Observation>& observations = (*observations_out)[i] =
        observeDetections(frames[i].detections, K.width, K.height, observe_options);
    if (odometry[i]) {
      (*tracks)[i] = track.add(observations, *odometry[i], gravity);
      results[i] = (*tracks)[i]->result;
    } else {
      track.reset();
      results[i] = relocalizer.relocalize(observations, {}, gravity);
    }
    if (references[i]) (*reference_scores)[i] = scoreReference(relocalizer, observations, *references[i]);
  }
  return results;
}

/// Observes and relocalizes every frame on `threads` worker threads; `observations` receives
/// each frame's observations, `reference_scores` the score of each frame's reference pose.
std::vector<RelocalizationResult> relocalizeFrames(
    const ObjectRelocalizer& relocalizer, const std::vector<DetectionFrame>& frames,
    const std::vector<std::vector<Keypoint>>& keypoints, const std::optional<GravityPrior>& gravity,
    const std::vector<std::optional<PoseRegion>>& regions, const ObserveOptions& observe_options,
    const std::vector<std::optional<Pose>>& references, int threads, const Console& console,
    std::vector<std::vector<Observation>>* observations_out, std::vector<ReferenceScore>* reference_scores) {
  // Frames are independent: `threads` workers take the next frame until none is left (the
  // calling thread only shows progress). The first exception of any worker stops the others
  // and is rethrown here, so a worker's failure is reported like the calling thread's.
  std::vector<RelocalizationResult> results(frames.size());
  const Intrinsics& K = relocalizer.intrinsics();
  std::atomic<size_t> next(0), finished(0);
  std::atomic<bool> failed(false);
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&] {
    try {
      for (size_t i = next++; i < frames.size() && !failed; i = next++) {
        const std::vector<Observation>& observations = (*observations_out)[i] =
            observeDetections(frames[i].detections, K.width, K.height, observe_options);
        results[i] = relocalizer.relocalize(observations, keypoints[i], gravity, regions[i]);
        if (references[i]) (*reference_scores)[i] = scoreReference(relocalizer, observations, *references[i]);
        ++finished;
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      failed = true;
    }
  };
  std::vector<std::thread> workers;
  if (threads <= 1) {
    work();
  } else {
    for (int t = 0; t < threads; ++t) workers.emplace_back(work);
    while (finished < frames.size() && !failed) {
      console.progress("relocalize", finished, frames.size());
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  for (std::thread& w : workers) w.join();
  if (failure) std::rethrow_exception(failure);
  return results;
}

/// How a frame's result compares with its reference pose: "valid" (within 30 cm and 30 deg of
/// it); "no pose" when none was returned; "search failure" when the reference explains the
/// frame better under our own cost, as given or refined (when refinement keeps it valid): we
/// never generated it; "scoring failure" when our wrong pose scores better than both: the
/// score cannot tell them apart.
std::string diagnose(const RelocalizationResult& result, const ReferenceScore& reference, const Pose& truth,
                     double unit_metres) {
  if (result.status != RelocalizationStatus::Success) return "no pose";
  if (poseError(result.pose, truth, unit_metres).valid()) return "valid";
  double best = reference.given.cost;
  if (reference.refined.status == RelocalizationStatus::Success &&
      poseError(reference.refined.pose, truth, unit_metres).valid())
    best = std::min(best, reference.refined.cost);
  return best < result.cost ? "search failure" : "scoring failure";
}

/// The options of --method, --max-time-ms, --envelope, --max-tilt and --no-map-envelope; `policy`
/// gets the method's default. `unit_metres`: the map's.
RelocalizerOptions relocalizerOptions(const RelocalizeArgs& a, double unit_metres, std::string* policy_out) {
  RelocalizerOptions options;
  if (a.method == "oa-slam") {
    options = RelocalizerOptions::oaSlam();
    if (policy_out->empty()) *policy_out = "bbox";
  } else if (a.method != "ours") {
    throw Error("--method: unknown method '" + a.method + "' (ours, oa-slam)");
  }
  // CLI11's range checks let NaN through.
  if (!std::isfinite(a.max_time_ms)) throw Error("--max-time-ms: expected a number of milliseconds, not NaN");
  if (!std::isfinite(a.min_evidence)) throw Error("--min-evidence: expected a number, not NaN");
  if (!std::isfinite(a.min_margin)) throw Error("--min-margin: expected a number, not NaN");
  options.search.budget.max_time_ms = a.max_time_ms;
  if (a.method == "ours") {
    options.acceptance.min_evidence = a.min_evidence;
    options.acceptance.min_margin = a.min_margin;
    options.acceptance.enabled = !a.accept_all;
  }
  if (a.no_map_envelope) options.map_envelope = false;
  if (!a.envelope.empty()) {
    std::vector<Pose> keyframes;
    for (const io::StampedPose& p : io::readTumTrajectory(a.envelope)) keyframes.push_back(p.pose);
    std::optional<Eigen::Vector3d> up;
    if (a.map_up.size() == 3) up = Eigen::Vector3d(a.map_up[0], a.map_up[1], a.map_up[2]);
    options.envelope = CameraEnvelope::fromKeyframes(keyframes, up, 0.5 / unit_metres);
    if (!options.envelope) throw Error(a.envelope + ": the envelope needs two poses and a non-zero up direction");
  }
  if (std::isnan(a.max_tilt_deg)) throw Error("--max-tilt: expected a number of degrees, not NaN");
  if (std::isnan(a.max_roll_deg)) throw Error("--max-roll: expected a number of degrees, not NaN");
  if (a.map_up.size() == 3 && a.camera_up.empty() && a.envelope.empty() && a.max_tilt_deg < 0.0)
    throw Error("--map-up alone does nothing: add --camera-up (gravity prior), --envelope or --max-tilt");
  if (a.max_tilt_deg >= 0.0) {
    options.envelope =
        CameraEnvelope::upright(Eigen::Vector3d(a.map_up[0], a.map_up[1], a.map_up[2]), a.max_tilt_deg, a.max_roll_deg);
    if (!options.envelope)
      throw Error(
          "--max-tilt/--max-roll/--map-up: expected a finite, non-zero up, a tilt in (0, 180] and a roll in (0, 90]");
  }
  if (const std::string problem = options.validate(); !problem.empty()) throw Error("options: " + problem);
  return options;
}

/// Each frame's timestamp, its file name's base name, under which its pose is written (as
/// that text): checked before any work, so every frame needs one and no two may share one.
std::vector<double> frameTimestamps(const std::vector<DetectionFrame>& frames, const std::string& path) {
  std::vector<double> timestamps;
  std::map<double, size_t> first;  // timestamp -> the first frame with it
  for (size_t i = 0; i < frames.size(); ++i) {
    const std::optional<double> t = frames[i].timestamp();
    const std::string where = path + ": [" + std::to_string(i) + "].file_name: '" + frames[i].file_name + "' ";
    if (!t) throw Error(where + "has no numeric base name to use as a timestamp");
    if (const auto [it, fresh] = first.emplace(*t, i); !fresh)
      throw Error(where + "has the timestamp of frame [" + std::to_string(it->second) + "]");
    timestamps.push_back(*t);
  }
  return timestamps;
}

/// Each frame's --near region: about the latest --near pose at or before the frame's timestamp,
/// none for a frame before the first; `without` counts those.
std::vector<std::optional<PoseRegion>> nearRegions(const RelocalizeArgs& a, const std::vector<double>& timestamps,
                                                   double unit_metres, size_t* without) {
  std::vector<std::optional<PoseRegion>> regions(timestamps.size());
  *without = 0;
  if (a.near.empty()) return regions;
  if (!(a.near_radius_m > 0.0) || !std::isfinite(a.near_radius_m))
    throw Error("--near-radius: expected a positive number of metres");
  if (!(a.near_angle_deg > 0.0 && a.near_angle_deg <= 180.0))  // CLI11's range check lets NaN through
    throw Error("--near-angle: expected a number of degrees in (0, 180]");
  std::vector<io::StampedPose> tracked = io::readTumTrajectory(a.near);
  std::stable_sort(tracked.begin(), tracked.end(),
                   [](const io::StampedPose& x, const io::StampedPose& y) { return x.timestamp < y.timestamp; });
  for (size_t i = 0; i < timestamps.size(); ++i) {
    // The last pose whose timestamp is not after the frame's (1 us for timestamps written alike).
    const auto after = std::upper_bound(tracked.begin(), tracked.end(), timestamps[i] + 1e-6,
                                        [](double t, const io::StampedPose& p) { return t < p.timestamp; });
    if (after == tracked.begin()) {
      ++*without;
      continue;
    }
    regions[i] = PoseRegion{std::prev(after)->pose, a.near_radius_m / unit_metres, a.near_angle_deg};
  }
  return regions;
}

/// Each frame's --track odometry pose: the one within 20 ms of its timestamp (none: the frame is
/// relocalized alone); `without` counts the frames without one.
std::vector<std::optional<Pose>> trackPoses(const RelocalizeArgs& a, const std::vector<double>& timestamps,
                                            size_t* without) {
  std::vector<std::optional<Pose>> poses(timestamps.size());
  *without = 0;
  if (a.track.empty()) return poses;
  const std::vector<io::StampedPose> odometry = io::readTumTrajectory(a.track);
  const io::TimeIndex by_time = io::timeIndex(odometry);
  for (size_t i = 0; i < timestamps.size(); ++i) {
    if (const auto k = by_time.nearest(timestamps[i]))
      poses[i] = odometry[*k].pose;
    else
      ++*without;
  }
  if (*without == timestamps.size() && !timestamps.empty())  // another sequence's poses, or other clock
    throw Error("--track: no frame has a pose in " + a.track + " within 20 ms of its timestamp");
  return poses;
}

/// Each frame's keypoints for --points: from the detections file itself, or from a file with the
/// same frames; none without --points. With a lens, moved to the pinhole image.
std::vector<std::vector<Keypoint>> frameKeypoints(const RelocalizeArgs& a, const ObjectMap& map,
                                                  const std::vector<DetectionFrame>& frames,
                                                  const std::optional<Lens>& lens) {
  std::vector<std::vector<Keypoint>> keypoints(frames.size());
  if (!a.use_points) return keypoints;
  if (map.points.empty()) throw Error(a.map + ": --points needs a map with `points`");
  std::map<std::string, std::vector<Keypoint>> by_name;
  if (!a.points.empty())
    for (const DetectionFrame& f : io::readDetections(a.points)) by_name[f.file_name] = f.keypoints;
  size_t left_out = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    keypoints[i] = a.points.empty() ? frames[i].keypoints : by_name[frames[i].file_name];
    if (lens) keypoints[i] = undistortKeypoints(*lens, keypoints[i], &left_out);
  }
  if (left_out > 0)
    std::fprintf(stderr, "warning: %zu keypoint(s) left out: beyond where the lens's distortion can be undone\n",
                 left_out);
  return keypoints;
}

/// How detections become observations: the policy, and with --undistort the camera file's lens.
ObserveOptions observeOptions(const RelocalizeArgs& a, const std::string& policy, const std::optional<Lens>& lens,
                              const Console& console) {
  ObserveOptions o;
  o.policy = parsePolicy(policy.empty() ? "solid" : policy);
  o.lens = lens;
  if (o.lens) {
    if (o.lens->distortion.isZero() && !console.quiet)
      std::printf("%s: no distortion (Camera.k1 ... all 0 or left out): --undistort changes nothing\n",
                  a.camera.c_str());
  } else if (!console.quiet) {
    mentionTheLens(a.camera);
  }
  return o;
}

/// One frame's entry of the --report JSON (with its diagnosis against a reference pose).
nlohmann::json frameReport(const DetectionFrame& frame, const RelocalizationResult& r, int observed,
                           const ObjectMap& map, const Pose* reference, const ReferenceScore& ref,
                           const std::string& diagnosis) {
  nlohmann::json j = {{"file_name", frame.file_name},
                      {"status", toString(r.status)},
                      {"reason", r.reason},
                      {"observations", observed},
                      {"inliers", r.inliers.size()},
                      {"score", r.cost},
                      {"mean_overlap", r.mean_overlap},
                      {"evidence", r.evidence},
                      {"margin", std::isfinite(r.margin) ? nlohmann::json(r.margin) : nlohmann::json()},
                      {"samples", r.iterations},
                      {"hypotheses", r.hypotheses},
                      {"budget_exhausted", r.budget_exhausted},
                      {"time_ms", r.time_ms}};
  nlohmann::json matches = nlohmann::json::array();
  for (const ObjectCorrespondence& c : r.inliers)
    matches.push_back({{"observation", c.observation},
                       {"object_id", map.objects[static_cast<size_t>(c.object)].id},
                       {"overlap", c.overlap}});
  j["matches"] = matches;
  const auto pose_json = [](const Pose& world_to_camera) {  // camera->world, as a TUM line has it
    const Pose camera_to_world = world_to_camera.inverse();
    const Eigen::Vector3d& c = camera_to_world.translation();
    const Eigen::Quaterniond q(camera_to_world.rotation());
    return nlohmann::json{{"position", {c.x(), c.y(), c.z()}}, {"quaternion", {q.x(), q.y(), q.z(), q.w()}}};
  };
  j["rival"] = r.rival ? pose_json(*r.rival) : nlohmann::json();
  j["alternatives"] = nlohmann::json::array();
  for (const ScoredPose& a : r.alternatives) {
    nlohmann::json alternative = pose_json(a.pose);
    alternative["score"] = a.cost;
    j["alternatives"].push_back(alternative);
  }
  if (reference) {
    j["reference"] = {{"score", ref.given.cost},
                      {"inliers", ref.given.inliers.size()},
                      {"refined_score", ref.refined.cost},
                      {"refined_inliers", ref.refined.inliers.size()},
                      {"refined_moved_cm", poseError(ref.refined.pose, *reference, map.unit_metres).position_cm},
                      {"diagnosis", diagnosis}};
    // The first valid alternative, the one a host checking them in turn would stop at; the
    // rival is the first alternative.
    size_t first_valid = 0;
    while (first_valid < r.alternatives.size() &&
           !poseError(r.alternatives[first_valid].pose, *reference, map.unit_metres).valid())
      ++first_valid;
    const bool any_valid = first_valid < r.alternatives.size();
    j["reference"]["valid_alternative"] = any_valid ? nlohmann::json(first_valid) : nlohmann::json();
    if (r.rival) j["reference"]["rival_valid"] = any_valid && first_valid == 0;
  }
  return j;
}

/// The --overlays folder, made before the relocalization so that a bad one fails before any output.
void makeOverlayFolder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir))
    throw FileError(dir + ": cannot create the overlays folder" + (ec ? ": " + ec.message() : std::string()));
}

/// The --overlays pictures, one per frame, named by the frame's timestamp, in a folder made by
/// makeOverlayFolder.
void writeOverlays(const RelocalizeArgs& a, const ObjectMap& map, const Intrinsics& K,
                   const std::vector<DetectionFrame>& frames, const std::vector<std::vector<Observation>>& observations,
                   const std::vector<RelocalizationResult>& results, const std::vector<std::optional<Pose>>& references,
                   const Lens* lens) {
  namespace fs = std::filesystem;
  const fs::path images = fs::path(a.detections).parent_path();
  for (size_t i = 0; i < frames.size(); ++i) {
    const RelocalizationResult& r = results[i];
    io::OverlayContent c;
    c.observations = observations[i];
    const bool has_pose = r.status == RelocalizationStatus::Success || r.status == RelocalizationStatus::LowEvidence;
    if (has_pose) c.pose = r.pose;
    c.truth = references[i];
    for (const ObjectCorrespondence& m : r.inliers) c.matches.emplace_back(m.observation, m.object);
    char line[160];
    c.text.push_back(frames[i].file_name + " (" + a.method + ")");
    char margin[32] = "none";  // no rival pose
    if (std::isfinite(r.margin)) std::snprintf(margin, sizeof margin, "%.2f", r.margin);
    std::snprintf(line, sizeof line, "%s: %zu of %zu matched, evidence %.2f, margin %s, %.1f ms", toString(r.status),
                  r.inliers.size(), c.observations.size(), r.evidence, margin, r.time_ms);
    c.text.push_back(line);
    if (has_pose && references[i]) {
      const PoseError e = poseError(r.pose, *references[i], map.unit_metres);
      std::snprintf(line, sizeof line, "against --reference: %.1f cm, %.1f deg (%s)", e.position_cm, e.rotation_deg,
                    e.valid() ? "valid" : "wrong");
      c.text.push_back(line);
    }
    const fs::path image = images / frames[i].file_name;
    std::error_code exists_ec;
    const bool found = !frames[i].file_name.empty() && fs::is_regular_file(image, exists_ec);
    io::writeOverlay((fs::path(a.overlays) / (frames[i].timestampText() + ".png")).string(), K, map, c,
                     found ? image.string() : "", lens);
  }
}

/// --camera-up, --map-up and --gravity-sigma as a prior for every frame, when both directions are given.
std::optional<GravityPrior> gravityPrior(const RelocalizeArgs& a) {
  if (a.camera_up.size() != 3 || a.map_up.size() != 3) return std::nullopt;
  const GravityPrior gravity{
      {a.camera_up[0], a.camera_up[1], a.camera_up[2]}, {a.map_up[0], a.map_up[1], a.map_up[2]}, a.gravity_sigma_deg};
  if (!gravity.isValid())
    throw Error("--camera-up/--map-up/--gravity-sigma: directions must be finite and non-zero, sigma positive");
  return gravity;
}

/// Each frame's --reference pose (the nearest in time, within the reader's tolerance), if any.
std::vector<std::optional<Pose>> referencePoses(const RelocalizeArgs& a, const std::vector<double>& timestamps) {
  std::vector<std::optional<Pose>> references(timestamps.size());
  if (a.reference.empty()) return references;
  const std::vector<io::StampedPose> trajectory = io::readTumTrajectory(a.reference, true);
  const io::TimeIndex by_time = io::timeIndex(trajectory);
  for (size_t i = 0; i < timestamps.size(); ++i)
    if (const auto k = by_time.nearest(timestamps[i])) references[i] = trajectory[*k].pose;
  return references;
}

/// The report's `track` entry of a frame relocalized along the track.
nlohmann::json trackReport(const TrackResult& t) {
  return {{"frames", t.frames},
          {"cost", t.track_cost},
          {"evidence", t.track_evidence},
          {"matches", t.track_matches},
          {"candidates", t.candidates},
          {"found_by", t.found_by},
          {"scale", t.scale}};
}

/// What the track's odometry gave: the frames without a pose, and the scale it was given in.
void printTrackSummary(const RelocalizeArgs& a, const std::vector<std::optional<TrackResult>>& tracks,
                       size_t without_odometry) {
  std::printf("%zu frame(s) without a pose of %s within 20 ms: relocalized alone, each starting the track again\n",
              without_odometry, a.track.c_str());
  if (!a.track_scale_unknown) return;
  std::vector<double> scales;
  for (const std::optional<TrackResult>& t : tracks)
    if (t && t->scale > 0.0) scales.push_back(t->scale);
  if (scales.empty())
    std::printf(
        "no scale found for %s: no two frames of a track had poses of their own that turned and moved as it does\n",
        a.track.c_str());
  else
    std::printf("scale of %s: median %.4g map units per odometry unit over the %zu tracked frame(s) that gave one\n",
                a.track.c_str(), median(scales), scales.size());
}

}  // namespace

int relocalize(const RelocalizeArgs& a, const Console& console) {
  checkPaths({{"--out", a.out}, {"--report", a.report}}, {{"--camera", a.camera},
                                                          {"--map", a.map},
                                                          {"--detections", a.detections},
                                                          {"--points", a.points},
                                                          {"--reference", a.reference},
                                                          {"--envelope", a.envelope},
                                                          {"--near", a.near},
                                                          {"--track", a.track}});
  if (!a.track.empty() && a.use_points) throw Error("--track: keypoints are not used along a track; drop --points");
  // With --undistort the camera file is read once, as a lens whose intrinsics are the pinhole image's.
  std::optional<Lens> lens;
  if (a.undistort) lens = io::readLens(a.camera);
  const Intrinsics K = lens ? lens->intrinsics : io::readCamera(a.camera);
  std::vector<std::string> left_out;
  const ObjectMap object_map = io::readMap(a.map, &left_out);
  for (const std::string& w : left_out) std::fprintf(stderr, "warning: %s\n", w.c_str());
  const std::vector<DetectionFrame> frames = io::readDetections(a.detections);
  const std::vector<double> timestamps = frameTimestamps(frames, a.detections);
  std::string policy = a.policy;
  const RelocalizerOptions options = relocalizerOptions(a, object_map.unit_metres, &policy);
  size_t without_region = 0;
  const std::vector<std::optional<PoseRegion>> regions =
      nearRegions(a, timestamps, object_map.unit_metres, &without_region);
  size_t without_odometry = 0;
  const std::vector<std::optional<Pose>> odometry = trackPoses(a, timestamps, &without_odometry);
  const ObserveOptions observe_options = observeOptions(a, policy, lens, console);
  const ObjectRelocalizer relocalizer(object_map, K, options);
  if (const auto& up = relocalizer.upFromObjects(); up && !console.quiet)
    std::printf(
        "%s has no camera envelope: the camera is kept upright, its horizon within %.0f degrees of level, about "
        "the up its objects tell: (%.3f, %.3f, %.3f), t = %.1f over %d objects (--no-map-envelope: anywhere)\n",
        a.map.c_str(), relocalizer.options().envelope->max_roll_deg, up->up.x(), up->up.y(), up->up.z(), up->t,
        up->objects);
  const std::optional<GravityPrior> gravity = gravityPrior(a);
  const std::vector<std::vector<Keypoint>> keypoints = frameKeypoints(a, object_map, frames, observe_options.lens);
  const std::vector<std::optional<Pose>> references = referencePoses(a, timestamps);

  if (!a.overlays.empty()) makeOverlayFolder(a.overlays);  // inputs read and checked: fail before the work
  std::vector<std::vector<Observation>> observations(frames.size());
  std::vector<ReferenceScore> reference_scores(frames.size());
  std::vector<std::optional<TrackResult>> tracks(frames.size());
  TrackOptions track_options;
  track_options.max_frames = a.track_frames;
  track_options.metric_odometry = !a.track_scale_unknown;
  const std::vector<RelocalizationResult> results =
      a.track.empty() ? relocalizeFrames(relocalizer, frames, keypoints, gravity, regions, observe_options, references,
                                         a.threads, console, &observations, &reference_scores)
                      : relocalizeAlongTrack(relocalizer, frames, timestamps, odometry, track_options, gravity,
                                             observe_options, references, &observations, &reference_scores, &tracks);
  console.endProgress();
  std::map<std::string, int> diagnoses;

  std::vector<io::StampedPose> poses;
  nlohmann::json report = nlohmann::json::array();
  std::vector<double> times;
  for (size_t i = 0; i < frames.size(); ++i) {
    const RelocalizationResult& r = results[i];
    times.push_back(r.time_ms);
    const Pose* reference = references[i] ? &*references[i] : nullptr;
    const std::string diagnosis = reference ? diagnose(r, reference_scores[i], *reference, object_map.unit_metres) : "";
    if (reference) ++diagnoses[diagnosis];
    nlohmann::json j = frameReport(frames[i], r, static_cast<int>(observations[i].size()), object_map, reference,
                                   reference_scores[i], diagnosis);
    if (const std::optional<TrackResult>& t = tracks[i]) j["track"] = trackReport(*t);
    report.push_back(j);
    if (r.status == RelocalizationStatus::Success) poses.push_back({timestamps[i], r.pose, frames[i].timestampText()});
  }
  io::writeTumTrajectory(a.out, poses);
  if (!a.overlays.empty())
    writeOverlays(a, object_map, K, frames, observations, results, references,
                  observe_options.lens ? &*observe_options.lens : nullptr);
  if (!a.report.empty()) io::writeFileAtomically(a.report, report.dump(1) + "\n");
  if (!console.quiet) {
    std::printf("wrote %s: %zu of %zu frames relocalized (%s), median %.1f ms per frame\n", a.out.c_str(), poses.size(),
                frames.size(), a.method.c_str(), median(times));
    const auto withheld = std::count_if(results.begin(), results.end(), [](const RelocalizationResult& r) {
      return r.status == RelocalizationStatus::LowEvidence;
    });
    if (withheld > 0)
      std::printf("%ld more pose(s) found but withheld as weakly supported (in --report; --accept-all writes them)\n",
                  static_cast<long>(withheld));
  }
  if (without_region > 0 && !console.quiet)
    std::printf("%zu frame(s) before the first pose of %s: searched everywhere\n", without_region, a.near.c_str());
  if (!a.track.empty() && !console.quiet) printTrackSummary(a, tracks, without_odometry);
  if (!a.reference.empty()) {  // a result: printed even when quiet
    std::printf("against %s:", a.reference.c_str());
    for (const auto& [diagnosis, count] : diagnoses) std::printf(" %s %d,", diagnosis.c_str(), count);
    std::printf(" no reference pose %zu\n",
                frames.size() - static_cast<size_t>(std::count_if(references.begin(), references.end(),
                                                                  [](const auto& p) { return p.has_value(); })));
  }
  return static_cast<int>(poses.size());
}

}  // namespace ellreloc::cli
