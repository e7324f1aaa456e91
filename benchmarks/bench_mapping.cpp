// Mapping speed: keyframes per second of the voxel mapper at 640x480 with 10 masked objects
// per keyframe (rendered office scene, mapping noise), on one core; memory per object; and what
// a host's correction of the keyframe poses costs.
//
//   build/benchmarks/bench_mapping --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include "ellreloc/mapping/mapper.hpp"
#include "fixtures/sim_sequence.hpp"

using namespace ellreloc;

namespace {

const test::SimSequence& sequence() {
  static const test::SimSequence seq = [] {
    test::SimSequence s = test::makeSimSequence(sim::ScenePreset::Office, 1, 40, test::mappingNoise());
    for (auto& kf : s.keyframes)
      if (kf.detections.size() > 10) kf.detections.resize(10);  // 10 masked objects per keyframe
    return s;
  }();
  return seq;
}

void BM_VoxelMapperKeyframe(benchmark::State& state) {
  const test::SimSequence& seq = sequence();
  double memory = 0, objects = 0;
  for (auto _ : state) {
    Mapper mapper(seq.K);
    for (const auto& kf : seq.keyframes) mapper.addKeyframe(kf.pose, kf.detections, &kf.depth);
    const MapperStats s = mapper.stats();
    memory = static_cast<double>(s.memory_bytes);
    objects = s.objects + s.candidates;
    benchmark::DoNotOptimize(s);
  }
  const double keyframes = static_cast<double>(seq.keyframes.size());
  state.counters["keyframes_per_s"] =
      benchmark::Counter(keyframes * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["kB_per_object"] = memory / objects / 1024.0;
}
BENCHMARK(BM_VoxelMapperKeyframe)->Unit(benchmark::kMillisecond);

void BM_BoxMapperKeyframe(benchmark::State& state) {
  const test::SimSequence& seq = sequence();
  MapperOptions opt;
  opt.mode = MappingMode::Boxes;
  for (auto _ : state) {
    Mapper mapper(seq.K, opt);
    for (const auto& kf : seq.keyframes) mapper.addKeyframe(kf.pose, kf.detections);
    benchmark::DoNotOptimize(mapper.stats());
  }
  state.counters["keyframes_per_s"] = benchmark::Counter(
      static_cast<double>(seq.keyframes.size()) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BoxMapperKeyframe)->Unit(benchmark::kMillisecond);

/// A host's correction of the same 40 keyframes (a loop closure: each pose moved by up to 2
/// degrees and 5 cm, then back): boxes mode fits every object again, voxel mode moves each
/// object's voxels.
void BM_UpdateKeyframePoses(benchmark::State& state) {
  const test::SimSequence& seq = sequence();
  MapperOptions opt;
  opt.mode = state.range(0) ? MappingMode::Boxes : MappingMode::Voxel;
  Mapper mapper(seq.K, opt);
  std::vector<Pose> poses, corrected;
  for (size_t i = 0; i < seq.keyframes.size(); ++i) {
    const auto& kf = seq.keyframes[i];
    mapper.addKeyframe(kf.pose, kf.detections, &kf.depth);
    const double share = static_cast<double>(i) / static_cast<double>(seq.keyframes.size());
    const Pose drift(Eigen::AngleAxisd(0.035 * share, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                     Eigen::Vector3d(0.05 * share, 0.0, 0.0));
    poses.push_back(kf.pose);
    corrected.push_back(kf.pose * drift);
  }
  mapper.finish();
  bool back = false;
  for (auto _ : state) {
    mapper.updateKeyframePoses(back ? poses : corrected);
    back = !back;
  }
  const MapperStats s = mapper.stats();
  state.counters["objects"] = s.objects;
  state.counters["voxels"] = static_cast<double>(s.voxels);
}
BENCHMARK(BM_UpdateKeyframePoses)->ArgName("boxes")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
