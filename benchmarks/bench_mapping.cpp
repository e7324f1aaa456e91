// Mapping speed: keyframes per second of the voxel mapper at 640x480 with 10 masked objects
// per keyframe (rendered office scene, mapping noise), on one core; memory per object.
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

}  // namespace

BENCHMARK_MAIN();
