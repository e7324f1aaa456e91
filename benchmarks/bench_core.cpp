// Core geometry in ns per call: projection, W2, Bhattacharyya, IoU, level-set distance.
// Run: ./build/benchmarks/bench_core --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "ellreloc/core.hpp"

using namespace ellreloc;

namespace {

struct Pairs {
  std::vector<Ellipse> a, b;
};

/// 1024 pairs of overlapping ellipses, as scoring a pose hypothesis produces them.
const Pairs& ellipsePairs() {
  static const Pairs pairs = [] {
    Pairs p;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pos(100, 500), ax(10, 100), ang(-3, 3), off(-30, 30);
    for (int i = 0; i < 1024; ++i) {
      const Ellipse e({pos(rng), pos(rng)}, {ax(rng), ax(rng)}, ang(rng));
      p.a.push_back(e);
      p.b.emplace_back(e.center() + Eigen::Vector2d(off(rng), off(rng)), Eigen::Vector2d(ax(rng), ax(rng)), ang(rng));
    }
    return p;
  }();
  return pairs;
}

template <typename F>
void runOnPairs(benchmark::State& state, F f) {
  const Pairs& p = ellipsePairs();
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f(p.a[i], p.b[i]));
    i = (i + 1) & 1023;
  }
}

void BM_Project(benchmark::State& state) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.5, 0.5), ax(0.05, 0.4);
  std::vector<Ellipsoid> ellipsoids;
  for (int i = 0; i < 1024; ++i) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(u(rng) * 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    ellipsoids.emplace_back(Eigen::Vector3d(u(rng) * 4, u(rng) * 3, 3.0 + u(rng) * 2),
                            Eigen::Vector3d(ax(rng), ax(rng), ax(rng)), R);
  }
  const Intrinsics K(525, 525, 319.5, 239.5, 640, 480);
  const Pose pose;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(project(ellipsoids[i], K, pose));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_Project);

void BM_Wasserstein2(benchmark::State& state) {
  runOnPairs(state, [](const Ellipse& a, const Ellipse& b) { return wasserstein2Squared(a, b); });
}
BENCHMARK(BM_Wasserstein2);

void BM_Bhattacharyya(benchmark::State& state) {
  runOnPairs(state, [](const Ellipse& a, const Ellipse& b) { return bhattacharyya(a, b); });
}
BENCHMARK(BM_Bhattacharyya);

void BM_EllipseIoU(benchmark::State& state) {
  const int vertices = static_cast<int>(state.range(0));
  runOnPairs(state, [vertices](const Ellipse& a, const Ellipse& b) { return ellipseIoU(a, b, vertices); });
}
BENCHMARK(BM_EllipseIoU)->Arg(32)->Arg(64)->Arg(128);

void BM_BoxIoU(benchmark::State& state) {
  runOnPairs(state, [](const Ellipse& a, const Ellipse& b) { return boxIoU(a.boundingBox(), b.boundingBox()); });
}
BENCHMARK(BM_BoxIoU);

void BM_LevelSet(benchmark::State& state) {
  runOnPairs(state, [](const Ellipse& a, const Ellipse& b) { return levelSetDistance(a, b); });
}
BENCHMARK(BM_LevelSet);

}  // namespace

BENCHMARK_MAIN();
