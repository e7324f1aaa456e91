// Finding each frame's pose in a trajectory by time, as `ellreloc map`, `relocalize --reference`
// and `evaluate` do: one pass over every pose per frame (io::findNearest) against the poses'
// times sorted once and searched (io::TimeIndex, the build of the index included). Frames 33 ms
// apart, each 4 ms from its pose; ms per whole sequence.
// Run: ./build/benchmarks/bench_io --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <vector>

#include "ellreloc/io/trajectory.hpp"

using namespace ellreloc;

namespace {

struct Sequence {
  std::vector<io::StampedPose> poses;
  std::vector<double> frame_times;
};

Sequence sequence(int n) {
  Sequence s;
  s.poses.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    s.poses[static_cast<size_t>(i)].timestamp = 1000.0 + 0.033 * i;
    s.frame_times.push_back(1000.0 + 0.033 * i + 0.004);
  }
  return s;
}

void BM_FramePoses(benchmark::State& state) {
  const Sequence s = sequence(static_cast<int>(state.range(1)));
  const bool indexed = state.range(0) != 0;
  for (auto _ : state) {
    size_t found = 0;
    if (indexed) {
      const io::TimeIndex by_time = io::timeIndex(s.poses);
      for (double t : s.frame_times) found += by_time.nearest(t).has_value();
    } else {
      for (double t : s.frame_times) found += io::findNearest(s.poses, t).has_value();
    }
    if (found != s.frame_times.size()) state.SkipWithError("a frame without its pose");
    benchmark::DoNotOptimize(found);
  }
}
BENCHMARK(BM_FramePoses)
    ->ArgNames({"indexed", "frames"})
    ->ArgsProduct({{0, 1}, {3000, 20000}})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
