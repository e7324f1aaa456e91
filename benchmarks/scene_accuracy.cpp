// Observations, voxel maps and relocalization scored on scene folders with ground truth
// (scene_folder.hpp: the independent renderer's scenes and `ellreloc simulate`'s output), so
// that every figure can be compared across simulators. Prints four markdown tables:
//   1. the regular-mask verdict against the truth (a convex quadrilateral outline), and the
//      quadrilateral test alone (which chooses the default policy's ellipse);
//   2. observation ellipses against the true projected ellipse: median W2(e, truth) / sqrt(ab)
//      of the truth, by true class, for the box-inscribed ellipse, the three mask policies,
//      and the box-inscribed ellipse scaled by the one factor that suits the scene best;
//   3. the voxel mapper (all mapping keyframes) against the true objects (expected: seen in >= 3 of them);
//   4. relocalization of the query frames with the perturbed map, the exact map and the voxel
//      map of table 3 (observations to map to pose, all from the scene's files): ours (with
//      and without the acceptance test), ours with the paper policy's observations, with box
//      observations and with the mask policy's (every mask fitted), the OA-SLAM preset, and the refiner's optimum at
//      the true pose with the matches found there (where the observations and the map put the pose when the search is
//      perfect) with the default and the mask policy; and ours with every detection of a true object observed as its
//      true projected ellipse (what the map alone allows).
// Run: build/benchmarks/scene_accuracy DIR [DIR...]
#include <cstdio>
#include <iterator>
#include <optional>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/evaluation.hpp"
#include "ellreloc/mapping/mapper.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/observe/regular_mask.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"
#include "map_scoring.hpp"
#include "scene_folder.hpp"

using namespace ellreloc;
using bench::medianOrNan;

namespace {

constexpr ObservationPolicy kPolicies[] = {ObservationPolicy::Bbox, ObservationPolicy::Paper, ObservationPolicy::Solid,
                                           ObservationPolicy::Mask};
/// Scales of the box-inscribed ellipse tried: how much larger than the projection of the
/// cuboid's inscribed ellipsoid the box's ellipse is, at best, for one factor.
constexpr double kBoxScales[] = {0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95, 1.0};

ObserveOptions withPolicy(ObservationPolicy policy) {
  ObserveOptions o;
  o.policy = policy;
  return o;
}

struct ObservationScores {
  int scored = 0, truly_regular = 0, flagged = 0, flagged_right = 0, right = 0;
  int quadrilateral = 0, quadrilateral_right = 0;   ///< the quadrilateral test alone: passed, and truly regular
  std::vector<double> w2[2][std::size(kPolicies)];  // [truly regular][policy of kPolicies]
  /// [truly regular][k]: the box-inscribed ellipse with its axes scaled by kBoxScales[k]
  std::vector<double> scaled_box_w2[2][std::size(kBoxScales)];
};

ObservationScores scoreObservations(const bench::SceneFolder& s) {
  ObservationScores sc;
  for (const DetectionFrame& f : s.query)
    for (const Detection& d : f.detections) {
      const Detection* truth = bench::truthOf(s.query_truth, f, d);
      if (!truth || !truth->ellipse || !truth->regular || !d.mask) continue;
      const bool regular = *truth->regular;
      const double scale = std::sqrt(truth->ellipse->axes().prod());
      if (const auto box = Ellipse::inscribedInBox(d.bbox))
        for (size_t k = 0; k < std::size(kBoxScales); ++k)
          sc.scaled_box_w2[regular][k].push_back(
              wasserstein2(Ellipse(box->center(), kBoxScales[k] * box->axes(), box->angle()), *truth->ellipse) / scale);
      for (size_t p = 0; p < std::size(kPolicies); ++p) {
        const ObserveResult r = observeDetection(d, s.K.width, s.K.height, withPolicy(kPolicies[p]));
        if (!r.observation) continue;
        sc.w2[regular][p].push_back(wasserstein2(r.observation->ellipse, *truth->ellipse) / scale);
        if (kPolicies[p] != ObservationPolicy::Paper) continue;
        const bool verdict = r.observation->regular.value_or(false);
        ++sc.scored;
        sc.truly_regular += regular;
        sc.flagged += verdict;
        sc.flagged_right += verdict && regular;
        sc.right += verdict == regular;
        const bool quadrilateral = testRegularMask(*d.mask).quadrilateral;
        sc.quadrilateral += quadrilateral;
        sc.quadrilateral_right += quadrilateral && regular;
      }
    }
  return sc;
}

void printVerdictRow(const std::string& scene, const ObservationScores& sc) {
  const auto ratio = [](int a, int b) { return b > 0 ? static_cast<double>(a) / b : 0.0; };
  std::printf("| %s | %d | %d | %.1f%% | %.2f | %.2f | %.2f | %.2f |\n", scene.c_str(), sc.scored, sc.truly_regular,
              100.0 * ratio(sc.right, sc.scored), ratio(sc.flagged_right, sc.flagged),
              ratio(sc.flagged_right, sc.truly_regular), ratio(sc.quadrilateral_right, sc.quadrilateral),
              ratio(sc.quadrilateral_right, sc.truly_regular));
}

void printEllipseRows(const std::string& scene, const ObservationScores& sc) {
  for (int regular = 1; regular >= 0; --regular) {
    const double box = medianOrNan(sc.w2[regular][0]);
    const double paper = medianOrNan(sc.w2[regular][1]), solid = medianOrNan(sc.w2[regular][2]);
    const double mask = medianOrNan(sc.w2[regular][3]);
    size_t best = 0;
    for (size_t k = 1; k < std::size(kBoxScales); ++k)
      if (medianOrNan(sc.scaled_box_w2[regular][k]) < medianOrNan(sc.scaled_box_w2[regular][best])) best = k;
    const double scaled = medianOrNan(sc.scaled_box_w2[regular][best]);
    std::printf("| %s | %s | %zu | %.3f | %.3f (%.2fx) | %.3f (%.2fx) | %.3f (%.2fx) | %.2f: %.3f (%.2fx) |\n",
                scene.c_str(), regular ? "regular" : "not regular", sc.w2[regular][0].size(), box, paper, paper / box,
                solid, solid / box, mask, mask / box, kBoxScales[best], scaled, scaled / box);
  }
}

/// Builds the voxel map of the mapping keyframes, prints its row and returns it.
ObjectMap scoreVoxelMap(const bench::SceneFolder& s) {
  std::map<int, int> seen;  // object id -> mapping keyframes with a detection of it
  for (const DetectionFrame& f : s.mapping_truth)
    for (const Detection& d : f.detections)
      if (d.object_id) ++seen[*d.object_id];
  std::vector<bench::TruthObject> truth;
  for (const MapObject& o : s.exact_map.objects) truth.push_back({o.category, o.ellipsoid, seen[o.id] >= 3});

  MapperOptions options;
  options.mode = MappingMode::Voxel;
  Mapper mapper(s.K, options);
  int keyframes = 0;
  for (const DetectionFrame& f : s.mapping) {
    const Pose* pose = io::framePose(s.mapping_poses, f);
    const auto depth = s.depth_of_rgb.find(f.file_name);
    if (!pose || depth == s.depth_of_rgb.end()) continue;
    const DepthImage image = io::readDepthPng(depth->second);
    mapper.addKeyframe(*pose, f.detections, &image);
    ++keyframes;
  }
  bench::MapErrors e;
  bench::scoreMap(mapper.map().objects, truth, &e);
  std::printf("| %s | %d | %d / %d | %.2f | %.2f | %.1f | %.1f | %.1f | %.1f |\n", s.name.c_str(), keyframes, e.found,
              e.expected, e.recall(), e.precision(), 100.0 * medianOrNan(e.centre), medianOrNan(e.yaw),
              100.0 * medianOrNan(e.axis), 100.0 * medianOrNan(e.axis_large));
  return mapper.map();
}

/// The refiner's optimum from the true pose with the matches the score finds there, taken
/// whatever its cost (each match weighed as the relocalizer's refinement weighs it): where the observation
/// ellipses and the map put the pose when the search is perfect. nullopt with fewer than two
/// matches, as the relocalizer's refinement.
std::optional<PoseError> refinerOptimumAtTruth(const ObjectRelocalizer& reloc, const std::vector<Observation>& obs,
                                               const Pose& truth) {
  const RelocalizationResult at_truth = reloc.scorePose(obs, truth);
  const std::vector<EllipseMatch> matches = reloc.refinementMatches(obs, at_truth.inliers);
  if (matches.size() < 2) return std::nullopt;
  return poseError(refinePose(reloc.intrinsics(), truth, matches, {}, reloc.options().refinement.refiner).pose, truth);
}

/// The query frame's observations under `policy`; with `true_ellipses`, each detection of a
/// true object takes its true projected ellipse instead (false positives keep theirs).
std::vector<Observation> observeFrame(const bench::SceneFolder& s, const DetectionFrame& f, ObservationPolicy policy,
                                      bool true_ellipses) {
  std::vector<Observation> out;
  for (const Detection& d : f.detections) {
    ObserveResult r = observeDetection(d, s.K.width, s.K.height, withPolicy(policy));
    if (!r.observation) continue;
    const Detection* truth = true_ellipses ? bench::truthOf(s.query_truth, f, d) : nullptr;
    if (truth && truth->ellipse && truth->object_id && *truth->object_id >= 0) {
      r.observation->ellipse = *truth->ellipse;
      r.observation->source = EllipseSource::Given;
      r.observation->regular.reset();
    }
    out.push_back(*r.observation);
  }
  return out;
}

void relocalizeRow(const bench::SceneFolder& s, const char* map_name, const ObjectMap& map, const char* method,
                   const RelocalizerOptions& options, ObservationPolicy policy, bool from_truth,
                   bool true_ellipses = false) {
  const ObjectRelocalizer reloc(map, s.K, options);
  std::vector<std::optional<PoseError>> errors;
  for (const DetectionFrame& f : s.query) {
    const Pose* truth = io::framePose(s.query_poses, f);
    if (!truth) continue;
    const std::vector<Observation> obs = observeFrame(s, f, policy, true_ellipses);
    if (from_truth) {
      errors.push_back(refinerOptimumAtTruth(reloc, obs, *truth));
      continue;
    }
    const RelocalizationResult r = reloc.relocalize(obs);
    errors.push_back(r.status == RelocalizationStatus::Success ? std::optional(poseError(r.pose, *truth))
                                                               : std::nullopt);
  }
  const RelocalizationSummary sum = summarize(errors);
  std::printf("| %s | %s | %s | %zu | %.1f%% | %.1f cm | %.2f deg |\n", s.name.c_str(), map_name, method, errors.size(),
              sum.validPercent(), sum.median_position_cm, sum.median_rotation_deg);
}

void scoreRelocalization(const bench::SceneFolder& s, const ObjectMap& voxel_map) {
  for (const auto& [map_name, map] : {std::pair<const char*, const ObjectMap*>{"perturbed", &s.perturbed_map},
                                      std::pair<const char*, const ObjectMap*>{"exact", &s.exact_map},
                                      std::pair<const char*, const ObjectMap*>{"voxel (table 3)", &voxel_map}}) {
    RelocalizerOptions every_pose;  // as the preset: no acceptance test withholding weak poses
    every_pose.acceptance.enabled = false;
    relocalizeRow(s, map_name, *map, "ours", RelocalizerOptions(), ObservationPolicy::Solid, false);
    relocalizeRow(s, map_name, *map, "ours, every pose", every_pose, ObservationPolicy::Solid, false);
    relocalizeRow(s, map_name, *map, "ours, every pose, paper policy", every_pose, ObservationPolicy::Paper, false);
    relocalizeRow(s, map_name, *map, "ours, every pose, box ellipses", every_pose, ObservationPolicy::Bbox, false);
    relocalizeRow(s, map_name, *map, "ours, every pose, mask policy", every_pose, ObservationPolicy::Mask, false);
    relocalizeRow(s, map_name, *map, "oa-slam preset", RelocalizerOptions::oaSlam(), ObservationPolicy::Bbox, false);
    relocalizeRow(s, map_name, *map, "the refiner's optimum at the true pose", every_pose, ObservationPolicy::Solid,
                  true);
    relocalizeRow(s, map_name, *map, "the refiner's optimum at the true pose, mask policy", every_pose,
                  ObservationPolicy::Mask, true);
    relocalizeRow(s, map_name, *map, "ours, every pose, true ellipses", every_pose, ObservationPolicy::Solid, false,
                  true);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // rows appear as they are measured
  if (argc < 2) {
    std::fprintf(stderr, "usage: scene_accuracy DIR [DIR...]  (scene folders, see benchmarks/scene_folder.hpp)\n");
    return 2;
  }
  std::vector<bench::SceneFolder> scenes;
  try {
    for (int i = 1; i < argc; ++i) scenes.push_back(bench::loadSceneFolder(argv[i]));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scene_accuracy: %s\n", e.what());
    return 1;
  }
  std::printf("Regular-mask verdict (policy paper) against the truth, query detections of true objects:\n\n");
  std::printf(
      "| scene | detections | truly regular | verdict right | precision | recall | quadrilateral test alone: precision "
      "| quadrilateral test alone: recall |\n|---|---|---|---|---|---|---|---|\n");
  std::vector<ObservationScores> observations;
  for (const auto& s : scenes) {
    observations.push_back(scoreObservations(s));
    printVerdictRow(s.name, observations.back());
  }
  std::printf(
      "\nObservation ellipses against the true projected ellipse, median W2 / sqrt(ab) of the truth (x the "
      "box's):\n\n");
  std::printf(
      "| scene | true class | masks | box-inscribed | policy paper | policy solid (default) | policy mask | "
      "box-inscribed, best scale |\n|---|---|---|---|---|---|---|---|\n");
  for (size_t i = 0; i < scenes.size(); ++i) printEllipseRows(scenes[i].name, observations[i]);
  std::printf(
      "\nVoxel map from every mapping keyframe against the true objects (recall: of those seen in at least 3):\n\n");
  std::printf(
      "| scene | keyframes | found | recall | precision | centre cm | yaw deg | axis %% | axis %% (>= 5 cm) |\n"
      "|---|---|---|---|---|---|---|---|---|\n");
  std::vector<ObjectMap> voxel_maps;
  for (const auto& s : scenes) voxel_maps.push_back(scoreVoxelMap(s));
  std::printf("\nRelocalization of the query frames (valid: within 30 cm and 30 deg):\n\n");
  std::printf(
      "| scene | map | method | frames | valid | median position | median rotation |\n|---|---|---|---|---|---|---|\n");
  for (size_t i = 0; i < scenes.size(); ++i) scoreRelocalization(scenes[i], voxel_maps[i]);
  return 0;
}
