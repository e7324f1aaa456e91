// Relocalization accuracy and time per query on real and synthetic data, ours against the
// OA-SLAM preset, in one run. Prints the rows of docs/benchmarks.md.
// Run: ./build/benchmarks/reloc_accuracy [data_dir]
#include <algorithm>
#include <cstdio>

#include "ellreloc/pose/object_relocalizer.hpp"
#include "relocalization_data.hpp"

using namespace ellreloc;

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

void evaluate(const char* name, const bench::RelocalizationDataset& d, const RelocalizerOptions& opt) {
  const ObjectRelocalizer reloc(d.map, d.K, opt);
  std::vector<double> pos, rot, times;
  int valid = 0;
  double max_time = 0.0;
  long hyps = 0;
  for (const auto& q : d.queries) {
    const RelocalizationResult r = reloc.relocalize(q.observations);
    times.push_back(r.time_ms);
    max_time = std::max(max_time, r.time_ms);
    hyps += r.hypotheses;
    if (r.status != RelocalizationStatus::Success) continue;
    const double pe = (r.pose.center() - q.truth.center()).norm();
    const double re = rotationErrorDeg(r.pose.rotation(), q.truth.rotation());
    if (pe < 0.3 && re < 30.0) {
      ++valid;
      pos.push_back(pe);
      rot.push_back(re);
    }
  }
  std::printf("| %-10s | %5.1f%% | %6.1f cm | %5.2f deg | %8.2f ms | %8.1f ms | %8ld |\n", name,
              100.0 * valid / d.queries.size(), 100.0 * median(pos), median(rot), median(times), max_time,
              hyps / static_cast<long>(d.queries.size()));
}

}  // namespace

int main(int argc, char** argv) {
  const std::string data = argc > 1 ? argv[1] : ELLRELOC_BENCH_DATA_DIR;
  const auto fr2 = bench::loadFr2Desk(data);
  std::printf("fr2_desk keyframes: %zu queries, %zu objects\n", fr2.queries.size(), fr2.map.objects.size());
  std::printf("| method     | valid  | median pos | median rot | median time | max time | hyp/query |\n");
  evaluate("ours", fr2, RelocalizerOptions());
  evaluate("oa-slam", fr2, RelocalizerOptions::oaSlam());
  if (getenv("VARIANTS")) {
    for (long t : {1000L, 3000L, 10000L}) {
      RelocalizerOptions o;
      o.max_exhaustive_triplets = t;
      evaluate(("exh<=" + std::to_string(t)).c_str(), fr2, o);
    }
    RelocalizerOptions o;
    o.overlap = OverlapMeasure::BoxIoU;
    evaluate("ours-box", fr2, o);
  }
  return 0;
}
