// Pose refinement and relocalization, microseconds per call.
// Run: ./build/benchmarks/bench_pose --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <random>

#include "ellreloc/core/projection.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/pose/wasserstein_refiner.hpp"

using namespace ellreloc;

namespace {

const Intrinsics kK(525.0, 525.0, 319.5, 239.5, 640, 480);

/// A room of n objects (categories 0..categories-1) on a 4 x 4 m floor plan, and camera poses
/// at 1.2-1.6 m height looking at the middle of the room.
struct Room {
  ObjectMap map;
  std::vector<Pose> cameras;
};

Room makeRoom(int n, int categories, int cameras, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Room room;
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(6.28 * u(rng), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d axes(0.05 + 0.25 * u(rng), 0.05 + 0.25 * u(rng), 0.05 + 0.2 * u(rng));
    room.map.objects.push_back(
        {i, i % categories, "", Ellipsoid({-1.5 + 3 * u(rng), -1.5 + 3 * u(rng), axes(2) + 0.75 * u(rng)}, axes, R)});
  }
  while (static_cast<int>(room.cameras.size()) < cameras) {
    const double a = 6.28 * u(rng);
    const Eigen::Vector3d c(2.8 * std::cos(a), 2.8 * std::sin(a), 1.2 + 0.4 * u(rng));
    const Eigen::Vector3d z = (Eigen::Vector3d(0.3 * u(rng), 0.3 * u(rng), 0.4) - c).normalized();
    const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
    Eigen::Matrix3d R_wc;
    R_wc << x, z.cross(x), z;
    room.cameras.push_back(Pose::fromCameraToWorld(R_wc, c));
  }
  return room;
}

/// Observations of up to `max_obs` visible objects with 1 px of centre noise and 3% axis noise.
std::vector<Observation> observe(const Room& room, const Pose& pose, int max_obs, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Observation> out;
  for (const MapObject& m : room.map.objects) {
    const Projection p = project(m.ellipsoid, kK, pose);
    if (!p) continue;
    const Box b = p.ellipse.boundingBox();
    if (b.x1 < 0 || b.y1 < 0 || b.x2 > kK.width || b.y2 > kK.height) continue;
    Observation o;
    o.category = m.category;
    o.ellipse = Ellipse(p.ellipse.center() + Eigen::Vector2d(g(rng), g(rng)), p.ellipse.axes() * (1.0 + 0.03 * g(rng)),
                        p.ellipse.angle());
    o.box = o.ellipse.boundingBox();
    out.push_back(o);
    if (static_cast<int>(out.size()) == max_obs) break;
  }
  return out;
}

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
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(refinePose(kK, starts[i], problems[i]));
    i = (i + 1) % problems.size();
  }
  state.counters["problems"] = static_cast<double>(problems.size());
}
BENCHMARK(BM_RefinePose10Objects)->Unit(benchmark::kMicrosecond);

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

}  // namespace

BENCHMARK_MAIN();
