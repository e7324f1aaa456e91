// P3P solvers side by side on the same random instances: ellreloc::p3p (Lambda Twist),
// OpenGV's p3p_kneip (when OpenGV is installed) and OpenCV's solveP3P with SOLVEPNP_AP3P.
// Speed: ns per solve. Accuracy: the *_Recovery benchmarks run 100,000 instances once and
// report the share where some solution has rotation error < 1e-6 rad (counter "recovered")
// and < 1e-6 degrees ("recovered_deg").
// Run: ./build/benchmarks/bench_p3p --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <opencv2/calib3d.hpp>

#include "ellreloc/core/p3p.hpp"
#include "fixtures/p3p_problems.hpp"
#ifdef ELLRELOC_HAVE_OPENGV
#include <opengv/absolute_pose/CentralAbsoluteAdapter.hpp>
#include <opengv/absolute_pose/methods.hpp>
#endif

#include <map>
#include <vector>

using namespace ellreloc;

namespace {

const std::vector<test::P3PInstance>& instances(double half_angle_deg, int n) {
  static std::map<std::pair<double, int>, std::vector<test::P3PInstance>> cache;
  auto& v = cache[{half_angle_deg, n}];
  if (v.empty()) {
    std::mt19937 rng(2024);
    for (int i = 0; i < n; ++i) v.push_back(test::randomP3PInstance(rng, half_angle_deg));
  }
  return v;
}

constexpr double kWide = 30.0, kNarrow = 1.0;  // half-angles of the bearing cone (degrees)

/// Each solver as: solve(instance) -> world->camera rotations.
std::vector<Eigen::Matrix3d> solveOurs(const test::P3PInstance& inst) {
  std::array<Pose, 4> poses;
  const int n = p3p(inst.bearings, inst.points, &poses);
  std::vector<Eigen::Matrix3d> out;
  for (int i = 0; i < n; ++i) out.push_back(poses[i].rotation());
  return out;
}

struct CvInput {
  cv::Mat object, image;
};
CvInput toCv(const test::P3PInstance& inst) {
  CvInput in{cv::Mat(3, 3, CV_64F), cv::Mat(3, 2, CV_64F)};
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) in.object.at<double>(i, k) = inst.points[i](k);
    in.image.at<double>(i, 0) = inst.bearings[i](0) / inst.bearings[i](2);
    in.image.at<double>(i, 1) = inst.bearings[i](1) / inst.bearings[i](2);
  }
  return in;
}
std::vector<Eigen::Matrix3d> solveOpenCv(const test::P3PInstance& inst) {
  const CvInput in = toCv(inst);
  std::vector<cv::Mat> rvecs, tvecs;
  cv::solveP3P(in.object, in.image, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), rvecs, tvecs, cv::SOLVEPNP_AP3P);
  std::vector<Eigen::Matrix3d> out;
  for (const cv::Mat& r : rvecs) {
    cv::Mat R;
    cv::Rodrigues(r, R);
    Eigen::Matrix3d E;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) E(a, b) = R.at<double>(a, b);
    out.push_back(E);
  }
  return out;
}

#ifdef ELLRELOC_HAVE_OPENGV
std::vector<Eigen::Matrix3d> solveOpenGv(const test::P3PInstance& inst) {
  const opengv::bearingVectors_t f(inst.bearings.begin(), inst.bearings.end());
  const opengv::points_t p(inst.points.begin(), inst.points.end());
  opengv::absolute_pose::CentralAbsoluteAdapter adapter(f, p);
  std::vector<Eigen::Matrix3d> out;
  // OpenGV returns [R_wc | centre]: transpose to world->camera.
  for (const auto& T : opengv::absolute_pose::p3p_kneip(adapter)) out.push_back(T.block<3, 3>(0, 0).transpose());
  return out;
}
#endif

template <typename Solver>
void recovery(benchmark::State& state, Solver solve, double half_angle) {
  const auto& insts = instances(half_angle, 100000);
  double rad = 0, deg = 0;
  for (auto _ : state) {
    int ok_rad = 0, ok_deg = 0;
    for (const auto& inst : insts) {
      double best = 1e9;
      for (const auto& R : solve(inst)) best = std::min(best, rotationErrorDeg(R, inst.truth.rotation()));
      ok_deg += best < 1e-6;
      ok_rad += best * M_PI / 180.0 < 1e-6;
    }
    rad = static_cast<double>(ok_rad) / insts.size();
    deg = static_cast<double>(ok_deg) / insts.size();
  }
  state.counters["recovered"] = rad;
  state.counters["recovered_deg"] = deg;
}

void BM_P3P_Ours(benchmark::State& state) {
  const auto& insts = instances(state.range(0) ? kNarrow : kWide, 1024);
  std::array<Pose, 4> poses;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(p3p(insts[i].bearings, insts[i].points, &poses));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_P3P_Ours)->ArgName("narrow")->Arg(0)->Arg(1);

void BM_P3P_OpenCvAP3P(benchmark::State& state) {
  const auto& insts = instances(state.range(0) ? kNarrow : kWide, 1024);
  std::vector<CvInput> in;
  for (const auto& inst : insts) in.push_back(toCv(inst));
  const cv::Mat K = cv::Mat::eye(3, 3, CV_64F);
  std::vector<cv::Mat> rvecs, tvecs;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        cv::solveP3P(in[i].object, in[i].image, K, cv::noArray(), rvecs, tvecs, cv::SOLVEPNP_AP3P));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_P3P_OpenCvAP3P)->ArgName("narrow")->Arg(0)->Arg(1);

#ifdef ELLRELOC_HAVE_OPENGV
void BM_P3P_OpenGvKneip(benchmark::State& state) {
  const auto& insts = instances(state.range(0) ? kNarrow : kWide, 1024);
  std::vector<opengv::bearingVectors_t> f;
  std::vector<opengv::points_t> p;
  for (const auto& inst : insts) {
    f.emplace_back(inst.bearings.begin(), inst.bearings.end());
    p.emplace_back(inst.points.begin(), inst.points.end());
  }
  std::vector<opengv::absolute_pose::CentralAbsoluteAdapter> adapters;
  for (size_t k = 0; k < insts.size(); ++k) adapters.emplace_back(f[k], p[k]);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(opengv::absolute_pose::p3p_kneip(adapters[i]));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_P3P_OpenGvKneip)->ArgName("narrow")->Arg(0)->Arg(1);
#endif

void BM_P3P_Recovery_Ours(benchmark::State& s) { recovery(s, solveOurs, s.range(0) ? kNarrow : kWide); }
BENCHMARK(BM_P3P_Recovery_Ours)->ArgName("narrow")->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kMillisecond);
void BM_P3P_Recovery_OpenCvAP3P(benchmark::State& s) { recovery(s, solveOpenCv, s.range(0) ? kNarrow : kWide); }
BENCHMARK(BM_P3P_Recovery_OpenCvAP3P)->ArgName("narrow")->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kMillisecond);
#ifdef ELLRELOC_HAVE_OPENGV
void BM_P3P_Recovery_OpenGvKneip(benchmark::State& s) { recovery(s, solveOpenGv, s.range(0) ? kNarrow : kWide); }
BENCHMARK(BM_P3P_Recovery_OpenGvKneip)->ArgName("narrow")->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kMillisecond);
#endif

}  // namespace

BENCHMARK_MAIN();
