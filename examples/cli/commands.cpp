#include "commands.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "ellreloc/ellreloc.hpp"

namespace fs = std::filesystem;

namespace ellreloc::cli {

void Console::progress(const char* what, size_t done, size_t total) const {
  if (quiet || !isatty(STDERR_FILENO) || total == 0) return;
  const int width = 30, filled = static_cast<int>(width * done / total);
  std::fprintf(stderr, "\r%-12s [%s%s] %zu/%zu", what, std::string(static_cast<size_t>(filled), '=').c_str(),
               std::string(static_cast<size_t>(width - filled), ' ').c_str(), done, total);
}

void Console::endProgress() const {
  if (!quiet && isatty(STDERR_FILENO)) std::fprintf(stderr, "\r%60s\r", "");
}

namespace {

std::string absoluteNormal(const fs::path& p) { return fs::absolute(p).lexically_normal().string(); }

double medianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

// --- simulate ------------------------------------------------------------------------------

void simulate(const SimulateArgs& a, const Console& console) {
  sim::SimulationOptions o;
  if (!sim::parsePreset(a.preset, &o.preset)) throw Error("--preset: unknown preset '" + a.preset + "'");
  if (!sim::parseNoiseLevel(a.noise, &o.noise)) throw Error("--noise: unknown noise level '" + a.noise + "'");
  o.seed = a.seed;
  o.mapping_frames = a.mapping_frames;
  o.query_frames = a.query_frames;
  const sim::SimulationSummary s = sim::writeSimulation(a.out, o);
  if (console.quiet) return;
  std::printf("wrote %s: %d objects, %d mapping frames, %d query frames (%d detections), %zu files\n", a.out.c_str(),
              s.objects, s.mapping_frames, s.query_frames, s.query_detections, s.files.size());
  for (const char* f :
       {"camera.yaml", "map_groundtruth.json", "map_perturbed.json", "mapping/associations.txt",
        "mapping/trajectory.txt", "mapping/detections.json", "query/detections.json", "query/groundtruth.txt"})
    std::printf("  %s/%s\n", a.out.c_str(), f);
}

// --- observe -------------------------------------------------------------------------------

namespace {
ObservationPolicy parsePolicy(const std::string& name) {
  if (name == "paper") return ObservationPolicy::Paper;
  if (name == "bbox") return ObservationPolicy::Bbox;
  if (name == "mask") return ObservationPolicy::Mask;
  if (name == "given") return ObservationPolicy::Given;
  throw Error("--policy: unknown policy '" + name + "' (paper, bbox, mask, given)");
}
}  // namespace

void observe(const ObserveArgs& a, const Console& console) {
  const Intrinsics K = io::readCamera(a.camera);
  std::vector<DetectionFrame> frames = io::readDetections(a.detections);
  ObserveOptions options;
  options.policy = parsePolicy(a.policy);
  int observed = 0, regular = 0, dropped = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    for (Detection& d : frames[i].detections) {
      const ObserveResult r = observeDetection(d, K.width, K.height, options);
      if (!r.observation) {
        ++dropped;
        continue;
      }
      d.ellipse = r.observation->ellipse;
      d.regular = r.observation->regular.value_or(false);
      regular += d.regular.value();
      ++observed;
    }
    console.progress("observe", i + 1, frames.size());
  }
  console.endProgress();
  io::writeDetections(a.out, frames);
  if (!console.quiet)
    std::printf("wrote %s: %d ellipses (%d regular masks), %d detections without an observation\n", a.out.c_str(),
                observed, regular, dropped);
}

// --- map -----------------------------------------------------------------------------------

void map(const MapArgs& a, const Console& console) {
  const Intrinsics K = io::readCamera(a.camera);
  MapperOptions options;
  if (!parseMappingMode(a.mode, &options.mode)) throw Error("--mode: unknown mode '" + a.mode + "' (voxel, boxes)");
  const std::vector<io::StampedPose> trajectory = io::readTumTrajectory(a.trajectory);
  const std::vector<DetectionFrame> frames = io::readDetections(a.detections);
  std::vector<io::Association> associations;
  if (!a.associations.empty()) associations = io::readAssociations(a.associations);
  if (options.mode == MappingMode::Voxel && associations.empty())
    throw Error(a.associations.empty() ? std::string("--associations: voxel mode needs the depth images")
                                       : a.associations + ": no association");
  const fs::path detections_dir = fs::path(a.detections).parent_path();

  Mapper mapper(K, options);
  int used = 0, no_pose = 0, no_depth = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const DetectionFrame& f = frames[i];
    // The frame's depth: the association naming the same colour image, else the same time.
    const std::string rgb = absoluteNormal(detections_dir / f.file_name);
    const io::Association* assoc = nullptr;
    for (const io::Association& as : associations)
      if (absoluteNormal(as.rgb_path) == rgb) assoc = &as;
    const std::optional<double> t = assoc ? std::optional<double>(assoc->rgb_time) : f.timestamp();
    if (!assoc && t)
      for (const io::Association& as : associations)
        if (std::abs(as.rgb_time - *t) <= 0.02) assoc = &as;
    const std::optional<size_t> k = t ? io::findNearest(trajectory, *t) : std::nullopt;
    if (!k) {
      ++no_pose;
      continue;
    }
    DepthImage depth;
    if (options.mode == MappingMode::Voxel) {
      if (!assoc) {
        ++no_depth;
        continue;
      }
      depth = io::readDepthPng(assoc->depth_path);
    }
    try {
      mapper.addKeyframe(trajectory[*k].pose, f.detections, options.mode == MappingMode::Voxel ? &depth : nullptr);
    } catch (const Error& e) {
      throw Error(a.detections + ": " + f.file_name + ": " + e.what());
    }
    ++used;
    console.progress("map", i + 1, frames.size());
  }
  console.endProgress();
  if (used == 0) throw Error(a.detections + ": no frame has both a pose in " + a.trajectory + " and its depth");
  const ObjectMap result = mapper.map();
  io::writeMap(a.out, result);
  if (!console.quiet)
    std::printf("wrote %s: %zu objects from %d keyframes (%s mode; %d frames without pose, %d without depth)\n",
                a.out.c_str(), result.objects.size(), used, a.mode.c_str(), no_pose, no_depth);
}

// --- relocalize ----------------------------------------------------------------------------

int relocalize(const RelocalizeArgs& a, const Console& console) {
  const Intrinsics K = io::readCamera(a.camera);
  const ObjectMap object_map = io::readMap(a.map);
  const std::vector<DetectionFrame> frames = io::readDetections(a.detections);
  RelocalizerOptions options;
  std::string policy = a.policy;
  if (a.method == "oa-slam") {
    options = RelocalizerOptions::oaSlam();
    if (policy.empty()) policy = "bbox";
  } else if (a.method != "ours") {
    throw Error("--method: unknown method '" + a.method + "' (ours, oa-slam)");
  }
  ObserveOptions observe_options;
  observe_options.policy = parsePolicy(policy.empty() ? "paper" : policy);
  const ObjectRelocalizer relocalizer(object_map, K, options);
  std::optional<GravityPrior> gravity;
  if (a.camera_up.size() == 3 && a.map_up.size() == 3) {
    gravity = GravityPrior{
        {a.camera_up[0], a.camera_up[1], a.camera_up[2]}, {a.map_up[0], a.map_up[1], a.map_up[2]}, a.gravity_sigma_deg};
    if (!gravity->isValid())
      throw Error("--camera-up/--map-up/--gravity-sigma: directions must be finite and non-zero, sigma positive");
  }
  // Keypoints per frame: from the detections file itself, or from a file with the same frames.
  std::vector<std::vector<Keypoint>> keypoints(frames.size());
  if (a.use_points) {
    if (object_map.points.empty()) throw Error(a.map + ": --points needs a map with `points`");
    std::map<std::string, std::vector<Keypoint>> by_name;
    if (!a.points.empty())
      for (const DetectionFrame& f : io::readDetections(a.points)) by_name[f.file_name] = f.keypoints;
    for (size_t i = 0; i < frames.size(); ++i)
      keypoints[i] = a.points.empty() ? frames[i].keypoints : by_name[frames[i].file_name];
  }

  // Frames are independent: workers take the next frame until none is left.
  std::vector<RelocalizationResult> results(frames.size());
  std::vector<int> observed(frames.size(), 0);
  std::atomic<size_t> next(0), finished(0);
  const auto work = [&] {
    for (size_t i = next++; i < frames.size(); i = next++) {
      std::vector<Observation> observations;
      for (const Detection& d : frames[i].detections)
        if (const ObserveResult r = observeDetection(d, K.width, K.height, observe_options); r.observation)
          observations.push_back(*r.observation);
      observed[i] = static_cast<int>(observations.size());
      results[i] = relocalizer.relocalize(observations, keypoints[i], gravity);
      ++finished;
    }
  };
  std::vector<std::thread> workers;
  for (int t = 1; t < a.threads; ++t) workers.emplace_back(work);
  if (a.threads <= 1) {
    work();
  } else {
    while (finished < frames.size()) {
      console.progress("relocalize", finished, frames.size());
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  for (std::thread& w : workers) w.join();
  console.endProgress();

  std::vector<io::StampedPose> poses;
  nlohmann::json report = nlohmann::json::array();
  std::vector<double> times;
  for (size_t i = 0; i < frames.size(); ++i) {
    const RelocalizationResult& r = results[i];
    times.push_back(r.time_ms);
    nlohmann::json j = {{"file_name", frames[i].file_name}, {"status", toString(r.status)}, {"reason", r.reason},
                        {"observations", observed[i]},      {"inliers", r.inliers.size()},  {"score", r.cost},
                        {"mean_overlap", r.mean_overlap},   {"hypotheses", r.hypotheses},   {"time_ms", r.time_ms}};
    nlohmann::json matches = nlohmann::json::array();
    for (const ObjectCorrespondence& c : r.inliers)
      matches.push_back({{"observation", c.observation},
                         {"object_id", object_map.objects[static_cast<size_t>(c.object)].id},
                         {"overlap", c.overlap}});
    j["matches"] = matches;
    report.push_back(j);
    if (r.status != RelocalizationStatus::Success) continue;
    const std::optional<double> t = frames[i].timestamp();
    if (!t)
      throw Error(a.detections + ": [" + std::to_string(i) + "].file_name: '" + frames[i].file_name +
                  "' has no numeric base name to use as a timestamp");
    poses.push_back({*t, r.pose});
  }
  io::writeTumTrajectory(a.out, poses);
  if (!a.report.empty()) io::writeFileAtomically(a.report, report.dump(1) + "\n");
  if (!console.quiet)
    std::printf("wrote %s: %zu of %zu frames relocalized (%s), median %.1f ms per frame\n", a.out.c_str(), poses.size(),
                frames.size(), a.method.c_str(), medianOf(times));
  return static_cast<int>(poses.size());
}

// --- evaluate ------------------------------------------------------------------------------

namespace {

/// A top view of the ground truth with the relocalized positions coloured by error, and the
/// cumulative error curves (the paper's Figs. 6 and 7), side by side.
void writePlot(const std::string& path, const std::vector<io::StampedPose>& gt,
               const std::vector<std::pair<Eigen::Vector3d, double>>& estimates, const std::vector<double>& pos_cm,
               const std::vector<double>& rot_deg, int frames) {
  const int size = 480;
  cv::Mat img(size, 2 * size, CV_8UC3, cv::Scalar(255, 255, 255));
  Eigen::AlignedBox2d box;
  for (const auto& p : gt) box.extend(p.pose.center().head<2>());
  for (const auto& [c, e] : estimates) box.extend(c.head<2>());
  const double span = std::max(1e-3, box.sizes().maxCoeff()) * 1.1;
  const Eigen::Vector2d mid = box.center();
  const auto px = [&](const Eigen::Vector3d& c) {
    return cv::Point(static_cast<int>(size / 2 + (c.x() - mid.x()) / span * (size - 40)),
                     static_cast<int>(size / 2 - (c.y() - mid.y()) / span * (size - 40)));
  };
  for (size_t i = 1; i < gt.size(); ++i)
    cv::line(img, px(gt[i - 1].pose.center()), px(gt[i].pose.center()), cv::Scalar(160, 160, 160), 1, cv::LINE_AA);
  for (const auto& [c, err_cm] : estimates) {
    const double s = std::min(1.0, err_cm / 30.0);  // green (0 cm) to red (>= 30 cm)
    cv::circle(img, px(c), 4, cv::Scalar(0, 255 * (1 - s), 255 * s), cv::FILLED, cv::LINE_AA);
  }
  cv::putText(img, "top view: ground truth (grey), relocalized (green 0 -> red 30 cm)", {8, 16},
              cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  // Cumulative curves: share of all frames with error below x (x from 0 to 30 cm / degrees).
  const cv::Point origin(size + 40, size - 40);
  const int w = size - 70, h = size - 90;
  cv::rectangle(img, origin, origin + cv::Point(w, -h), cv::Scalar(0, 0, 0));
  const auto curve = [&](std::vector<double> v, const cv::Scalar& colour) {
    std::sort(v.begin(), v.end());
    cv::Point last = origin;
    for (int x = 0; x <= w; ++x) {
      const double limit = 30.0 * x / w;
      const double share = static_cast<double>(std::upper_bound(v.begin(), v.end(), limit) - v.begin()) / frames;
      const cv::Point p(origin.x + x, origin.y - static_cast<int>(share * h));
      if (x > 0) cv::line(img, last, p, colour, 2, cv::LINE_AA);
      last = p;
    }
  };
  curve(pos_cm, cv::Scalar(200, 80, 0));
  curve(rot_deg, cv::Scalar(0, 120, 0));
  cv::putText(img, "cumulative share of frames: position error (cm, blue), rotation error (deg, green)", {size + 8, 16},
              cv::FONT_HERSHEY_SIMPLEX, 0.35, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, "0", origin + cv::Point(-4, 16), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0));
  cv::putText(img, "30", origin + cv::Point(w - 8, 16), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0));
  cv::putText(img, "100%", origin + cv::Point(-36, -h + 4), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0));
  std::vector<uchar> png;
  if (!cv::imencode(".png", img, png)) throw Error(path + ": could not encode the plot");
  io::writeFileAtomically(path, std::string(png.begin(), png.end()));
}

}  // namespace

Evaluation evaluate(const EvaluateArgs& a) {
  const std::vector<io::StampedPose> gt = io::readTumTrajectory(a.groundtruth);
  const std::vector<io::StampedPose> est = io::readTumTrajectory(a.estimate);
  // The query frames: those of the detections file when given, else every ground-truth pose.
  std::vector<double> queries;
  if (!a.detections.empty()) {
    for (const DetectionFrame& f : io::readDetections(a.detections))
      if (const auto t = f.timestamp(); t && io::findNearest(gt, *t)) queries.push_back(*t);
  } else {
    for (const io::StampedPose& p : gt) queries.push_back(p.timestamp);
  }
  if (queries.empty()) throw Error(a.groundtruth + ": no query frame has a ground-truth pose");
  Evaluation e;
  e.frames = static_cast<int>(queries.size());
  std::vector<double> pos_cm, rot_deg, valid_pos, valid_rot;
  std::vector<std::pair<Eigen::Vector3d, double>> estimates;
  for (double t : queries) {
    const auto g = io::findNearest(gt, t);
    const auto k = io::findNearest(est, t, 1e-4);
    if (!g || !k) continue;
    ++e.relocalized;
    const Pose& truth = gt[*g].pose;
    const Pose& mine = est[*k].pose;
    const double dp = 100.0 * (mine.center() - truth.center()).norm();
    const double dr = rotationErrorDeg(mine.rotation(), truth.rotation());
    pos_cm.push_back(dp);
    rot_deg.push_back(dr);
    estimates.emplace_back(mine.center(), dp);
    if (dp < 30.0 && dr < 30.0) {  // FORMATS.md: valid within 30 cm and 30 degrees
      ++e.valid;
      valid_pos.push_back(dp);
      valid_rot.push_back(dr);
    }
  }
  e.median_position_cm = medianOf(valid_pos);
  e.median_rotation_deg = medianOf(valid_rot);
  if (!a.plot.empty()) writePlot(a.plot, gt, estimates, pos_cm, rot_deg, e.frames);
  return e;
}

void printEvaluation(const Evaluation& e) {
  std::printf("| median position error (cm) | median rotation error (deg) | valid %% | relocalized |\n");
  std::printf("| --- | --- | --- | --- |\n");
  std::printf("| %.1f | %.2f | %.1f | %d / %d |\n", e.median_position_cm, e.median_rotation_deg, e.validPercent(),
              e.relocalized, e.frames);
}

// --- demo ----------------------------------------------------------------------------------

void demo(const DemoArgs& a, const Console& console) {
  const std::string dir = a.out.empty() ? (fs::temp_directory_path() / "ellreloc-demo").string() : a.out;
  const Console inner{true};  // the demo prints its own summary
  const auto t0 = std::chrono::steady_clock::now();
  if (!console.quiet) std::printf("1. simulating an office (20 objects, realistic noise) in %s\n", dir.c_str());
  simulate({"office", "realistic", dir, a.seed, 60, 100}, inner);
  if (!console.quiet) std::printf("2. mapping it from 60 RGB-D keyframes with masks (voxel mode)\n");
  map({dir + "/camera.yaml", dir + "/mapping/associations.txt", dir + "/mapping/trajectory.txt",
       dir + "/mapping/detections.json", "voxel", dir + "/map_voxel.json"},
      inner);
  const size_t objects = io::readMap(dir + "/map_voxel.json").objects.size();
  struct Row {
    const char* name;
    std::string map, method;
  };
  const Row rows[] = {{"ours, voxel map", dir + "/map_voxel.json", "ours"},
                      {"OA-SLAM, voxel map", dir + "/map_voxel.json", "oa-slam"},
                      {"ours, perturbed true map", dir + "/map_perturbed.json", "ours"},
                      {"OA-SLAM, perturbed true map", dir + "/map_perturbed.json", "oa-slam"}};
  if (!console.quiet)
    std::printf("3. relocalizing 100 query frames (other heights and headings) with both methods\n\n");
  std::printf("| method, map | median position error (cm) | median rotation error (deg) | valid %% |\n");
  std::printf("| --- | --- | --- | --- |\n");
  for (const Row& r : rows) {
    const std::string out = dir + "/poses_" + r.method + "_" + fs::path(r.map).stem().string() + ".txt";
    RelocalizeArgs args;
    args.camera = dir + "/camera.yaml";
    args.map = r.map;
    args.detections = dir + "/query/detections.json";
    args.method = r.method;
    args.out = out;
    args.threads = a.threads;
    relocalize(args, inner);
    const Evaluation e = evaluate({dir + "/query/groundtruth.txt", out, dir + "/query/detections.json", ""});
    std::printf("| %s | %.1f | %.2f | %.1f |\n", r.name, e.median_position_cm, e.median_rotation_deg, e.validPercent());
    std::fflush(stdout);
  }
  if (!console.quiet)
    std::printf("\nvoxel map: %zu objects; files in %s; %.0f s\n", objects, dir.c_str(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

}  // namespace ellreloc::cli
