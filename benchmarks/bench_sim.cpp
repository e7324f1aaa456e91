// Rendering one 640x480 frame (instance masks as RLE, boxes, depth) of the synthetic presets.
// Run: ./build/benchmarks/bench_sim --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "ellreloc/sim/render.hpp"
#include "ellreloc/sim/scene.hpp"

using namespace ellreloc;

namespace {

void BM_Render(benchmark::State& state) {
  const auto preset = static_cast<sim::ScenePreset>(state.range(0));
  const sim::Scene scene = sim::makeScene(preset, 1);
  const auto poses = sim::queryTrajectory(scene, 32, 2);
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(sim::render(scene, K, poses[i]));
    i = (i + 1) % poses.size();
  }
  state.SetLabel(sim::toString(preset));
}
BENCHMARK(BM_Render)
    ->Arg(static_cast<int>(sim::ScenePreset::Office))
    ->Arg(static_cast<int>(sim::ScenePreset::Cluttered))
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
