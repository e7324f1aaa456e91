// One observation from a 640x480 instance mask holding one ~200x150 object: ours (RLE decode of
// the object's crop + regular test + fit) against OpenCV's findContours + fitEllipse on the
// already decoded image (which favours OpenCV: it skips the decoding).
// Run: ./build/benchmarks/bench_observe --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <opencv2/imgproc.hpp>

#include "ellreloc/observe/observe.hpp"

using namespace ellreloc;

namespace {

/// A perspective quadrilateral (regular) or an ellipse with a bump (irregular), ~200 x 150.
BinaryMask makeMask(bool regular) {
  BinaryMask m(480, 640);
  const Eigen::Vector2d q[4] = {{220, 170}, {425, 185}, {410, 320}, {230, 305}};
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      bool in;
      if (regular) {
        in = true;
        for (int k = 0; k < 4; ++k) {
          const Eigen::Vector2d a = q[k], b = q[(k + 1) % 4];
          in = in && (b(0) - a(0)) * (y - a(1)) - (b(1) - a(1)) * (x - a(0)) >= 0;
        }
      } else {
        const double u = (x - 320) / 100.0, v = (y - 240) / 75.0;
        in = u * u + v * v <= 1.0 || ((x - 400) * (x - 400) + (y - 200) * (y - 200) <= 900);
      }
      m.at(x, y) = in;
    }
  return m;
}

void BM_ObserveOurs(benchmark::State& state) {
  const BinaryMask m = makeMask(state.range(0));
  Detection d;
  d.category_id = 62;
  d.mask = encodeMask(m);
  d.bbox = rleMoments(*d.mask)->bounds;
  ObserveOptions opt;
  constexpr ObservationPolicy kPolicies[] = {ObservationPolicy::Mask, ObservationPolicy::Paper,
                                             ObservationPolicy::Solid};
  opt.policy = kPolicies[state.range(1)];
  for (auto _ : state) benchmark::DoNotOptimize(observeDetection(d, 640, 480, opt));
}
// policy 0: `mask` (always fit the mask); 1: `paper` (irregular masks keep the box); 2: `solid`
// (the default: solid irregular masks, as this one, are fitted too)
BENCHMARK(BM_ObserveOurs)
    ->ArgNames({"regular", "policy"})
    ->Args({1, 2})
    ->Args({0, 2})
    ->Args({0, 1})
    ->Args({0, 0})
    ->Unit(benchmark::kMicrosecond);

void BM_ObserveOpenCv(benchmark::State& state) {
  const BinaryMask m = makeMask(state.range(0));
  cv::Mat img(480, 640, CV_8U);
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) img.at<uint8_t>(y, x) = m.at(x, y) ? 255 : 0;
  for (auto _ : state) {
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(img, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    benchmark::DoNotOptimize(cv::fitEllipse(contours.at(0)));
  }
}
BENCHMARK(BM_ObserveOpenCv)->ArgName("regular")->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
