// `ellreloc map`.

#include "ellreloc/io/map.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <utility>

#include "commands.hpp"
#include "ellreloc/core/coco.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "ellreloc/mapping/map_quality.hpp"
#include "ellreloc/mapping/mapper.hpp"

namespace fs = std::filesystem;

namespace ellreloc::cli {

namespace {

/// "1 object", "2 objects".
std::string counted(size_t n, const std::string& noun) { return std::to_string(n) + " " + noun + (n == 1 ? "" : "s"); }

/// The frames that have a pose in the trajectory, with that pose; with a lens, their boxes
/// undistorted (one that cannot be, far outside the image, is left out).
std::vector<PosedDetections> posedFrames(const std::vector<DetectionFrame>& frames,
                                         const std::vector<io::StampedPose>& trajectory,
                                         const io::TimeIndex& by_time, const std::optional<Lens>& lens) {
  std::vector<PosedDetections> out;
  for (const DetectionFrame& f : frames)
    if (const Pose* pose = io::framePose(trajectory, by_time, f)) {
      out.push_back({*pose, {}});
      for (Detection d : f.detections) {
        if (lens) {
          const std::optional<Box> box = lens->undistortBox(d.bbox);
          if (!box) continue;
          d.bbox = *box;
        }
        out.back().detections.push_back(std::move(d));
      }
    }
  return out;
}

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

/// Printed even when quiet: it is a result.
void printQuality(const MapQuality& q) {
  std::printf(
      "map quality on %zu held-out frames: median best same-category IoU %.3f (mean %.3f) over %zu boxes, "
      "%zu overlap an object of their category\n",
      q.frames, q.median_best_iou, q.mean_best_iou, q.boxes, q.explained);
}

/// Objects per category, what was left out, and the candidates that never entered the map.
void printSummary(const ObjectMap& map, const std::vector<std::string>& dropped, const MapperStats& stats,
                  int min_observations, double unit_metres, std::optional<double> unit_told) {
  std::map<int, int> per_category;
  for (const MapObject& o : map.objects) ++per_category[o.category];
  std::string line;
  for (const auto& [category, count] : per_category) {
    const char* name = cocoCategoryName(category);
    line += (line.empty() ? "" : ", ") + std::to_string(count) + " " +
            (name ? std::string(name) : "category " + std::to_string(category));
  }
  std::printf("  objects: %s\n", line.empty() ? "none" : line.c_str());
  std::printf(
      "  left out: %zu degenerate object(s)%s%s; %d candidate(s) seen fewer than %d times or fitting no ellipsoid\n",
      dropped.size(), dropped.empty() ? "" : ": ", joined(dropped).c_str(), stats.candidates, min_observations);
  if (stats.placed_by_size > 0)
    std::printf(
        "  %d object(s) placed by their category's typical size: seen over too narrow a baseline to triangulate\n",
        stats.placed_by_size);
  if (const auto& e = map.camera_envelope)
    std::printf(
        "  camera envelope (relocalization keeps to it): heights %.2f to %.2f m along up (%.3f, %.3f, %.3f), "
        "tilts %.0f to %.0f deg\n",
        e->min_height * unit_metres, e->max_height * unit_metres, e->up(0), e->up(1), e->up(2), e->min_tilt_deg,
        e->max_tilt_deg);
  if (unit_told && std::abs(*unit_told / unit_metres - 1.0) <= 0.02)
    std::printf("  the objects' sizes tell %.3g m per unit of the trajectory, the unit taken\n", *unit_told);
  else if (unit_told)
    std::printf(
        "  the objects' sizes tell %.3g m per unit of the trajectory (taken: %.3g; for poses of unknown "
        "scale, --unit-metres auto)\n",
        *unit_told, unit_metres);
}

}  // namespace

CLI::App* addMapCommand(CLI::App& app, MapArgs& a) {
  CLI::App* m = app.add_subcommand("map", "build an object map from keyframes (docs/mapping.md)");
  m->add_option("--camera", a.camera, "camera intrinsics: ORB-SLAM YAML or JSON")->required()->check(CLI::ExistingFile);
  m->add_option("--associations", a.associations, "TUM association file (voxel mode: the depth images)")
      ->check(CLI::ExistingFile);
  m->add_option("--trajectory", a.trajectory, "TUM trajectory of the keyframes (camera->world)")
      ->required()
      ->check(CLI::ExistingFile);
  m->add_option("--detections", a.detections, "detections with masks (voxel) or boxes")
      ->required()
      ->check(CLI::ExistingFile);
  m->add_option("--mode", a.mode, "voxel (RGB-D + masks) or boxes (boxes and poses only)")->capture_default_str();
  m->add_option("--out", a.out, "output map JSON")->required();
  m->add_option("--up", a.up,
                "the world's up direction (against gravity), e.g. 0,0,1: box-mode ellipsoids stand upright (yaw "
                "only); voxel mode takes it as the ellipsoids' up")
      ->expected(3)
      ->delimiter(',');
  m->add_flag("--undistort", a.undistort,
              "the detections (and depth images) are raw images of a distorted lens: undistort them with the "
              "--camera file's Camera.k1, k2, p1, p2, k3 (left out: 0)");
  m->add_option("--unit-metres", a.unit_metres,
                "boxes mode: the length of the trajectory's unit in metres, for a monocular SLAM system's poses; "
                "auto: the unit the objects' sizes tell (the frames mapped again until it settles)")
      ->capture_default_str();
  m->add_option("--detections-out", a.detections_out,
                "write the detections again, each box's object_id the map object it joined (left out for a box "
                "that joined none of the map's objects, or was not mapped)");
  m->add_option("--holdout-every", a.holdout_every,
                "leave every N-th frame out of the map and report how well the map explains its boxes")
      ->check(CLI::Range(2, 1000000));
  m->add_option("--holdout", a.holdout,
                "detections of frames not used for mapping (poses from --trajectory): report how well the map "
                "explains their boxes")
      ->check(CLI::ExistingFile);
  m->footer(
      "Example: ellreloc map --camera S/camera.yaml --associations S/mapping/associations.txt --trajectory "
      "S/mapping/trajectory.txt --detections S/mapping/detections.json --mode voxel --out map.json");
  return m;
}

/// What `map` reads besides the camera: the trajectory, the frames and where their depth images are.
struct MapInputs {
  std::vector<io::StampedPose> trajectory;
  io::TimeIndex by_time;
  std::vector<DetectionFrame> frames;
  io::AssociationIndex association_of;
  fs::path detections_dir;
};

/// One pass over the frames: the mapper, and what it could not use.
struct MappingPass {
  std::unique_ptr<Mapper> mapper;
  int used = 0, no_pose = 0, no_depth = 0;
  std::vector<PosedDetections> held_out;  // --holdout-every's frames
  std::vector<std::vector<int>> object_ids;  // per frame, its report's (empty: not mapped)
};

MappingPass mapFrames(const MapArgs& a, const MapperOptions& options, const Intrinsics& K, const MapInputs& in,
                      const Console& console) {
  MappingPass pass;
  pass.mapper = std::make_unique<Mapper>(K, options);
  pass.object_ids.resize(in.frames.size());
  for (size_t i = 0; i < in.frames.size(); ++i) {
    const DetectionFrame& f = in.frames[i];
    if (a.holdout_every > 0 && i % static_cast<size_t>(a.holdout_every) == static_cast<size_t>(a.holdout_every) - 1) {
      std::vector<PosedDetections> one = posedFrames({f}, in.trajectory, in.by_time, options.lens);
      pass.held_out.insert(pass.held_out.end(), one.begin(), one.end());
      continue;
    }
    // The frame's depth: the association naming the same colour image, else the nearest time.
    const io::Association* assoc = in.association_of.find((in.detections_dir / f.file_name).string(), f.timestamp());
    const std::optional<double> t = assoc ? std::optional<double>(assoc->rgb_time) : f.timestamp();
    const std::optional<size_t> k = t ? in.by_time.nearest(*t) : std::nullopt;
    if (!k) {
      ++pass.no_pose;
      continue;
    }
    DepthImage depth;
    if (options.mode == MappingMode::Voxel) {
      if (!assoc) {
        ++pass.no_depth;
        continue;
      }
      depth = io::readDepthPng(assoc->depth_path);
    }
    try {
      pass.object_ids[i] =
          pass.mapper
              ->addKeyframe(in.trajectory[*k].pose, f.detections, options.mode == MappingMode::Voxel ? &depth : nullptr)
              .object_ids;
    } catch (const Error& e) {
      throw Error(a.detections + ": " + f.file_name + ": " + e.what());
    }
    ++pass.used;
    console.progress("map", i + 1, in.frames.size());
  }
  console.endProgress();
  if (pass.used == 0)
    throw Error(a.detections + ": no frame has " +
                (options.mode == MappingMode::Voxel ? "both a pose in " + a.trajectory + " and its depth"
                                                    : "a pose in " + a.trajectory + " (within 0.02 s)"));
  pass.mapper->finish();
  return pass;
}

/// --unit-metres: a length in metres, or nullopt for "auto".
std::optional<double> unitGiven(const std::string& text, MappingMode mode) {
  char* end = nullptr;
  const double unit = text == "auto" ? 0.0 : std::strtod(text.c_str(), &end);
  if (text != "auto" && (text.empty() || *end != '\0' || !validUnitMetres(unit)))
    throw Error("--unit-metres: expected metres (1e-6 to 1e6) or auto, got '" + text + "'");
  if (mode == MappingMode::Voxel && unit != 1.0)
    throw Error("--unit-metres: boxes mode only (voxel mode's depth images are in metres)");
  if (text == "auto") return std::nullopt;
  return unit;
}

/// With --unit-metres auto, the frames are mapped taking a unit of 1 m, then again with the unit
/// the objects tell, until it settles (within 2%, at most four passes in all).
MappingPass mapInTheUnit(const MapArgs& a, MapperOptions& options, const Intrinsics& K, const MapInputs& in,
                         const Console& console) {
  const std::optional<double> given = unitGiven(a.unit_metres, options.mode);
  options.unit_metres = given.value_or(1.0);
  MappingPass pass = mapFrames(a, options, K, in, console);
  for (int passes = 1; !given && passes < 4; ++passes) {
    const std::optional<double> told = pass.mapper->estimatedUnitMetres();
    if (!told || std::abs(*told / options.unit_metres - 1.0) <= 0.02) break;
    options.unit_metres = *told;
    if (!console.quiet) std::printf("mapping again in a unit of %.3g m\n", *told);
    pass = mapFrames(a, options, K, in, console);
  }
  return pass;
}

/// --detections-out: the frames with each box's object_id the map object it joined, if any.
void writeAssociatedDetections(const std::string& path, std::vector<DetectionFrame> frames, const MappingPass& pass,
                               const ObjectMap& map) {
  std::set<int> in_map;
  for (const MapObject& o : map.objects) in_map.insert(o.id);
  for (size_t i = 0; i < frames.size(); ++i)
    for (size_t j = 0; j < frames[i].detections.size(); ++j) {
      std::optional<int>& id = frames[i].detections[j].object_id;
      id.reset();
      if (j < pass.object_ids[i].size() && pass.object_ids[i][j] >= 0)
        if (const std::optional<int> now = pass.mapper->currentObjectId(pass.object_ids[i][j]);
            now && in_map.count(*now))
          id = now;
    }
  io::writeDetections(path, frames);
}

void map(const MapArgs& a, const Console& console) {
  checkPaths({{"--out", a.out}, {"--detections-out", a.detections_out}}, {{"--camera", a.camera},
                                                                          {"--associations", a.associations},
                                                                          {"--trajectory", a.trajectory},
                                                                          {"--detections", a.detections},
                                                                          {"--holdout", a.holdout}});
  MapperOptions options;
  // With --undistort the camera file is read once, as a lens whose intrinsics are the pinhole image's.
  if (a.undistort) options.lens = io::readLens(a.camera);
  const Intrinsics K = options.lens ? options.lens->intrinsics : io::readCamera(a.camera);
  if (!parseMappingMode(a.mode, &options.mode)) throw Error("--mode: unknown mode '" + a.mode + "' (voxel, boxes)");
  unitGiven(a.unit_metres, options.mode);  // refused before any file is read
  if (!a.up.empty()) {
    const Eigen::Vector3d up(a.up[0], a.up[1], a.up[2]);
    if (!up.allFinite() || !(up.norm() > 1e-9)) throw Error("--up: not a direction (finite, non-zero)");
    options.ellipsoid.up = up.normalized();
    options.boxes.up = up.normalized();
  }
  if (!a.undistort && !console.quiet) mentionTheLens(a.camera);
  std::vector<io::StampedPose> trajectory = io::readTumTrajectory(a.trajectory);
  std::vector<DetectionFrame> frames = io::readDetections(a.detections);
  std::vector<io::Association> associations;
  if (!a.associations.empty()) associations = io::readAssociations(a.associations);
  if (options.mode == MappingMode::Voxel && associations.empty())
    throw Error(a.associations.empty() ? std::string("--associations: voxel mode needs the depth images")
                                       : a.associations + ": no association");
  const io::TimeIndex by_time = io::timeIndex(trajectory);
  const MapInputs in{std::move(trajectory), by_time, std::move(frames), io::AssociationIndex(std::move(associations)),
                     fs::path(a.detections).parent_path()};

  std::vector<PosedDetections> held_out;
  if (!a.holdout.empty())
    held_out = posedFrames(io::readDetections(a.holdout), in.trajectory, in.by_time, options.lens);
  MappingPass pass = mapInTheUnit(a, options, K, in, console);
  held_out.insert(held_out.end(), pass.held_out.begin(), pass.held_out.end());
  ObjectMap result = pass.mapper->map();
  // Objects relocalization could not use (mapObjectProblem) are left out of the file, and said.
  std::vector<std::string> dropped;
  result.objects.erase(std::remove_if(result.objects.begin(), result.objects.end(),
                                      [&](const MapObject& o) {
                                        const std::string why = mapObjectProblem(o, result.unit_metres);
                                        if (!why.empty()) dropped.push_back(std::to_string(o.id) + " (" + why + ")");
                                        return !why.empty();
                                      }),
                       result.objects.end());
  io::writeMap(a.out, result);
  if (!a.detections_out.empty()) writeAssociatedDetections(a.detections_out, in.frames, pass, result);
  if (!console.quiet) {
    // Boxes mode reads no depth: only voxel mode can miss one.
    const std::string no_depth_text =
        options.mode == MappingMode::Voxel ? ", " + std::to_string(pass.no_depth) + " without depth" : "";
    std::printf("wrote %s: %s from %s (%s mode; %s without pose%s)\n", a.out.c_str(),
                counted(result.objects.size(), "object").c_str(), counted(pass.used, "keyframe").c_str(),
                a.mode.c_str(), counted(pass.no_pose, "frame").c_str(), no_depth_text.c_str());
    printSummary(result, dropped, pass.mapper->stats(), options.min_observations, options.unit_metres,
                 pass.mapper->estimatedUnitMetres());
  }
  if (!a.holdout.empty() || a.holdout_every > 0) printQuality(measureMapQuality(result, K, held_out));
}

}  // namespace ellreloc::cli
