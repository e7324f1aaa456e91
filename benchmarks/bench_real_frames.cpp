// Relocalization time on real frames, one frame at a time: the median and 90th percentile per frame, ours
// beside the OA-SLAM preset in the same run.
//   fr2   every fr2_desk keyframe (198) against the real GOReloc map
//   fr3   every 10th frame of the odd frames of the fr3/long_office first half (129) against a map
//         built from its even frames by the boxes mapper (motion-capture poses)
//   fr3 whole half   every 5th frame of that half (259) against the boxes map of all its frames, the
//         map a host builds from a whole sequence (more objects, more look-alikes; the frames are
//         in-sample, so this row measures time, not accuracy); ours only, the preset taking
//         about 20x as long
// Ours also with each frame's hypotheses split over 2 threads (search.threads), and on fr2 with an
// upright camera (CameraEnvelope::upright: the map's up is -y, its first keyframe's image-up) or
// with an IMU's gravity (GravityPrior at each keyframe's pose, about the keyframes' mean image-up).
// Run: ./build/benchmarks/bench_real_frames --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "ellreloc/mapping/mapper.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"

using namespace ellreloc;

namespace {

const std::string kData = ELLRELOC_BENCH_DATA_DIR;

struct RealSet {
  Intrinsics K;
  ObjectMap map;
  std::vector<std::vector<Observation>> frames;
  std::vector<GravityPrior> gravity;  ///< fr2: what an IMU would measure at each frame's pose
};

RealSet fr2() {
  RealSet s;
  const std::string d = kData + "/tum_fr2_desk";
  s.K = io::readCamera(d + "/camera.yaml");
  s.map = io::readMap(d + "/map.json");
  const std::vector<io::StampedPose> poses = io::readTumTrajectory(d + "/keyframes.groundtruth.txt");
  const std::vector<DetectionFrame> frames = io::readDetections(d + "/keyframes.detections.json");
  // The map is in its first camera's frame: gravity is about the keyframes' mean image-up (-y).
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const io::StampedPose& p : poses) up -= p.pose.rotation().row(1).transpose();
  for (const DetectionFrame& f : frames) {
    s.frames.push_back(observeDetections(f.detections, s.K.width, s.K.height));
    const Pose* pose = io::framePose(poses, f);
    s.gravity.push_back(pose ? GravityPrior::atPose(*pose, up.normalized(), 1.0) : GravityPrior{});
  }
  return s;
}

/// The fr3 first half: a boxes map of every `map_step`-th frame from `map_first`, queried on every
/// `query_step`-th frame from `query_first`.
RealSet fr3(size_t map_first, size_t map_step, size_t query_first, size_t query_step) {
  RealSet s;
  const std::string d = kData + "/tum_fr3_office_first_half";
  s.K = io::readCamera(d + "/camera.yaml");
  const std::vector<io::StampedPose> truth = io::readTumTrajectory(d + "/groundtruth.txt");
  const std::vector<DetectionFrame> frames = io::readDetections(d + "/detections.json");
  MapperOptions options;
  options.mode = MappingMode::Boxes;
  Mapper mapper(s.K, options);
  for (size_t i = map_first; i < frames.size(); i += map_step)
    if (const Pose* pose = io::framePose(truth, frames[i])) mapper.addKeyframe(*pose, frames[i].detections);
  mapper.finish();
  s.map = mapper.map();
  for (size_t i = query_first; i < frames.size(); i += query_step)
    s.frames.push_back(observeDetections(frames[i].detections, s.K.width, s.K.height));
  return s;
}

/// Loaded (and for fr3 mapped) on first use only.
const RealSet& realSet(int which) {
  if (which == 0) {
    static const RealSet set = fr2();
    return set;
  }
  if (which == 1) {
    static const RealSet set = fr3(0, 2, 1, 10);  // map the even frames, query odd ones
    return set;
  }
  static const RealSet set = fr3(0, 1, 0, 5);  // map every frame, query every 5th
  return set;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

/// One frame per iteration, every frame once per repetition; the counters give the median and
/// the 90th percentile of the frames' times. state.range(0): the OA-SLAM preset; range(1): the
/// threads that split each frame's hypotheses (search.threads). `up`: the map's up, for a camera
/// that is never upside down; `with_gravity`: each frame with its set's gravity prior.
void relocalizeEveryFrame(benchmark::State& state, const RealSet& set,
                          const std::optional<Eigen::Vector3d>& up = std::nullopt, bool with_gravity = false) {
  RelocalizerOptions options = state.range(0) ? RelocalizerOptions::oaSlam() : RelocalizerOptions();
  options.search.threads = static_cast<int>(state.range(1));
  if (up) options.envelope = CameraEnvelope::upright(*up);
  const ObjectRelocalizer reloc(set.map, set.K, options);
  std::vector<double> times;
  size_t i = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    if (with_gravity)
      benchmark::DoNotOptimize(reloc.relocalize(set.frames[i], {}, set.gravity[i]));
    else
      benchmark::DoNotOptimize(reloc.relocalize(set.frames[i]));
    times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    i = (i + 1) % set.frames.size();
  }
  state.counters["median_ms"] = percentile(times, 0.5);
  state.counters["p90_ms"] = percentile(times, 0.9);
}

void BM_Fr2Keyframes(benchmark::State& state) {
  relocalizeEveryFrame(state, realSet(0),
                       state.range(2) ? std::optional<Eigen::Vector3d>(-Eigen::Vector3d::UnitY()) : std::nullopt);
}
BENCHMARK(BM_Fr2Keyframes)
    ->ArgNames({"oaslam", "threads", "upright"})
    ->Args({0, 1, 0})
    ->Args({0, 2, 0})
    ->Args({1, 1, 0})
    ->Args({0, 1, 1})
    ->Iterations(198)
    ->Unit(benchmark::kMillisecond);

void BM_Fr2KeyframesGravity(benchmark::State& state) { relocalizeEveryFrame(state, realSet(0), std::nullopt, true); }
BENCHMARK(BM_Fr2KeyframesGravity)
    ->ArgNames({"oaslam", "threads"})
    ->Args({0, 1})
    ->Iterations(198)
    ->Unit(benchmark::kMillisecond);

void BM_Fr3Frames(benchmark::State& state) { relocalizeEveryFrame(state, realSet(1)); }
BENCHMARK(BM_Fr3Frames)
    ->ArgNames({"oaslam", "threads"})
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 1})
    ->Iterations(129)
    ->Unit(benchmark::kMillisecond);

void BM_Fr3WholeHalfMap(benchmark::State& state) { relocalizeEveryFrame(state, realSet(2)); }
BENCHMARK(BM_Fr3WholeHalfMap)
    ->ArgNames({"oaslam", "threads"})
    ->Args({0, 1})
    ->Args({0, 2})
    ->Iterations(259)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
