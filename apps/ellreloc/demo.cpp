// `ellreloc demo`.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "ellreloc/io/map.hpp"

namespace fs = std::filesystem;

namespace ellreloc::cli {

CLI::App* addDemoCommand(CLI::App& app, DemoArgs& a) {
  CLI::App* d =
      app.add_subcommand("demo", "simulate -> map -> relocalize (ours and OA-SLAM) -> evaluate -> report.html");
  d->add_option("--out", a.out, "working folder (default: a folder in the system's temp directory)");
  d->add_option("--seed", a.seed, "seed of the simulated scene")->capture_default_str();
  d->add_option("--threads", a.threads, "frames relocalized in parallel")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  d->footer("Example: ellreloc demo --out /tmp/ellreloc-demo");
  return d;
}

void demo(const DemoArgs& a, const Console& console) {
  const std::string dir = a.out.empty() ? (fs::temp_directory_path() / "ellreloc-demo").string() : a.out;
  const Console inner{true};  // the demo prints its own summary
  const auto t0 = std::chrono::steady_clock::now();
  if (!console.quiet) std::printf("1. simulating an office (20 objects, realistic noise) in %s\n", dir.c_str());
  simulate({"office", "realistic", dir, a.seed, 60, 100}, inner);
  if (!console.quiet) std::printf("2. mapping it from 60 RGB-D keyframes with masks (voxel mode)\n");
  map({dir + "/camera.yaml", dir + "/mapping/associations.txt", dir + "/mapping/trajectory.txt",
       dir + "/mapping/detections.json", "voxel", dir + "/map_voxel.json"},
      inner);
  const size_t objects = io::readMap(dir + "/map_voxel.json").objects.size();
  struct Row {
    const char* name;
    std::string map, method;
  };
  const Row rows[] = {{"ours, voxel map", dir + "/map_voxel.json", "ours"},
                      {"OA-SLAM, voxel map", dir + "/map_voxel.json", "oa-slam"},
                      {"ours, perturbed true map", dir + "/map_perturbed.json", "ours"},
                      {"OA-SLAM, perturbed true map", dir + "/map_perturbed.json", "oa-slam"}};
  if (!console.quiet)
    std::printf("3. relocalizing 100 query frames (other heights and headings) with both methods\n\n");
  // Wrong poses (reported, but off by more than 30 cm or 30 degrees) beside the valid share: ours
  // withholds weakly supported poses, OA-SLAM reports every pose it finds.
  std::printf("| method, map | median position error (cm) | median rotation error (deg) | valid %% | wrong poses |\n");
  std::printf("| --- | --- | --- | --- | --- |\n");
  for (const Row& r : rows) {
    const std::string out = dir + "/poses_" + r.method + "_" + fs::path(r.map).stem().string() + ".txt";
    RelocalizeArgs args;
    args.camera = dir + "/camera.yaml";
    args.map = r.map;
    args.detections = dir + "/query/detections.json";
    args.method = r.method;
    args.out = out;
    args.threads = a.threads;
    if (r.map == rows[0].map && r.method == "ours") args.overlays = dir + "/overlays";
    relocalize(args, inner);
    EvaluateArgs ev;
    ev.groundtruth = dir + "/query/groundtruth.txt";
    ev.estimates = {out};
    ev.detections = dir + "/query/detections.json";
    const RelocalizationSummary e = evaluate(ev).methods[0].summary;
    std::printf("| %s | %.1f | %.2f | %.1f | %d |\n", r.name, e.median_position_cm, e.median_rotation_deg,
                e.validPercent(), e.relocalized - e.valid);
    std::fflush(stdout);
  }
  // The report compares both methods on the voxel map, with the overlays of ours' worst frames.
  ReportArgs report_args;
  report_args.groundtruth = dir + "/query/groundtruth.txt";
  report_args.estimates = {dir + "/poses_ours_map_voxel.txt:ours", dir + "/poses_oa-slam_map_voxel.txt:OA-SLAM"};
  report_args.detections = dir + "/query/detections.json";
  report_args.map = dir + "/map_voxel.json";
  report_args.overlays = dir + "/overlays";
  report_args.out = dir + "/report.html";
  report(report_args, inner);
  if (!console.quiet)
    std::printf("\nvoxel map: %zu objects; files in %s; report: %s; %.0f s\n", objects, dir.c_str(),
                report_args.out.c_str(), std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

}  // namespace ellreloc::cli
