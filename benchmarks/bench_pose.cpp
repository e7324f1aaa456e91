// Pose refinement and relocalization, microseconds per call.
// Run: ./build/benchmarks/bench_pose --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <random>

#include "ellreloc/core/projection.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/pose/wasserstein_refiner.hpp"
#include "synthetic_room.hpp"

using namespace ellreloc;
using namespace ellreloc::bench;

namespace {

void BM_RefinePose10Objects(benchmark::State& state) {
  const Room room = makeRoom(60, 10, 64, 1);
  std::mt19937 rng(2);
  std::vector<std::vector<EllipseMatch>> problems;
  std::vector<Pose> starts;
  for (const Pose& truth : room.cameras) {
    std::vector<EllipseMatch> matches;
    for (const Observation& o : observe(room, truth, 1000, rng)) {
      for (const MapObject& m : room.map.objects) {
        const Projection p = project(m.ellipsoid, kK, truth);
        if (p && (p.ellipse.center() - o.ellipse.center()).norm() < 5 && m.category == o.category) {
          matches.push_back({o.ellipse, m.ellipsoid});
          break;
        }
      }
      if (matches.size() == 10) break;
    }
    if (matches.size() < 10) continue;
    problems.push_back(matches);
    const Eigen::Matrix3d dR = Eigen::AngleAxisd(0.03, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    starts.push_back(Pose(dR * truth.rotation(), truth.translation() + Eigen::Vector3d(0.03, -0.02, 0.04)));
  }
  RefinerOptions opt;
  if (state.range(0)) opt.backend = RefinerBackend::Ceres;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(refinePose(kK, starts[i], problems[i], {}, opt));
    i = (i + 1) % problems.size();
  }
  state.counters["problems"] = static_cast<double>(problems.size());
}
BENCHMARK(BM_RefinePose10Objects)->ArgName("ceres")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

/// 47 objects, 12 observations per query (the fr2_desk map's size), ours vs the OA-SLAM preset.
void BM_Relocalize47x12(benchmark::State& state) {
  const Room room = makeRoom(47, 19, 200, 3);  // 19 categories, as in the fr2_desk map
  std::mt19937 rng(4);
  std::vector<std::vector<Observation>> queries;
  for (const Pose& p : room.cameras) {
    auto obs = observe(room, p, 12, rng);
    if (obs.size() == 12) queries.push_back(obs);
  }
  const ObjectRelocalizer reloc(room.map, kK, state.range(0) ? RelocalizerOptions::oaSlam() : RelocalizerOptions());
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(reloc.relocalize(queries[i]));
    i = (i + 1) % queries.size();
  }
  state.counters["queries"] = static_cast<double>(queries.size());
}
BENCHMARK(BM_Relocalize47x12)->ArgName("oaslam")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// The worst case a host must survive: 200 objects of one category, 50 observations (the visible
/// objects and clutter), default options: the work bound limits the search (docs/reliability.md).
void BM_RelocalizeWorstCase200x50(benchmark::State& state) {
  const Room room = makeRoom(200, 1, 20, 5);
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::vector<Observation>> queries;
  for (const Pose& p : room.cameras) {
    auto obs = observe(room, p, 50, rng);
    while (obs.size() < 50) {  // clutter of the same category
      Observation o;
      o.category = 0;
      o.ellipse = Ellipse({640 * u(rng), 480 * u(rng)}, {5 + 40 * u(rng), 5 + 20 * u(rng)}, u(rng));
      o.box = o.ellipse.boundingBox();
      obs.push_back(o);
    }
    queries.push_back(obs);
  }
  const ObjectRelocalizer reloc(room.map, kK);
  size_t i = 0;
  double hypotheses = 0;
  for (auto _ : state) {
    const RelocalizationResult r = reloc.relocalize(queries[i]);
    hypotheses = static_cast<double>(r.hypotheses);
    i = (i + 1) % queries.size();
  }
  state.counters["hypotheses"] = hypotheses;
}
BENCHMARK(BM_RelocalizeWorstCase200x50)->Iterations(5)->Unit(benchmark::kMillisecond);

/// Absurd input a host must still survive (docs/reliability.md): N objects of one category and
/// M observations of it, ours and the OA-SLAM preset, default options. One frame each; the
/// counter peak_MB is the process's peak memory so far (the largest case runs last).
void BM_RelocalizeHugeFrame(benchmark::State& state) {
  const int objects = static_cast<int>(state.range(0)), observations = static_cast<int>(state.range(1));
  const Room room = makeRoom(objects, 1, 1, 7);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Observation> frame = observe(room, room.cameras[0], observations, rng);
  while (static_cast<int>(frame.size()) < observations) {  // clutter of the same category
    Observation o;
    o.category = 0;
    o.ellipse = Ellipse({640 * u(rng), 480 * u(rng)}, {5 + 40 * u(rng), 5 + 20 * u(rng)}, u(rng));
    o.box = o.ellipse.boundingBox();
    frame.push_back(o);
  }
  const ObjectRelocalizer reloc(room.map, kK, state.range(2) ? RelocalizerOptions::oaSlam() : RelocalizerOptions());
  RelocalizationResult r;
  for (auto _ : state) r = reloc.relocalize(frame);
  struct rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["hypotheses"] = static_cast<double>(r.hypotheses);
  state.counters["skipped"] = static_cast<double>(r.skipped.size());
  state.counters["peak_MB"] = static_cast<double>(usage.ru_maxrss) / 1024.0;
}
BENCHMARK(BM_RelocalizeHugeFrame)
    ->ArgNames({"objects", "observations", "oaslam"})
    ->Args({2000, 1000, 0})
    ->Args({2000, 1000, 1})
    ->Args({10000, 10000, 0})
    ->Args({10000, 10000, 1})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
