// `ellreloc simulate`.

#include <CLI/CLI.hpp>
#include <cstdio>

#include "commands.hpp"
#include "ellreloc/sim/writer.hpp"

namespace ellreloc::cli {

CLI::App* addSimulateCommand(CLI::App& app, SimulateArgs& a) {
  CLI::App* s = app.add_subcommand("simulate", "write a synthetic scene in the TUM layout (docs/simulator.md)");
  s->add_option("--preset", a.preset, "office, cluttered or sparse")->capture_default_str();
  s->add_option("--seed", a.seed, "same seed, same files")->capture_default_str();
  s->add_option("--noise", a.noise, "none, realistic or hard")->capture_default_str();
  s->add_option("--out", a.out, "output folder (created)")->required();
  s->add_option("--mapping-frames", a.mapping_frames, "keyframes of the mapping loop")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  s->add_option("--query-frames", a.query_frames, "query frames from other heights and headings")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  s->footer("Example: ellreloc simulate --preset office --seed 1 --noise realistic --out /tmp/office");
  return s;
}

void simulate(const SimulateArgs& a, const Console& console) {
  sim::SimulationOptions o;
  if (!sim::parsePreset(a.preset, &o.preset)) throw Error("--preset: unknown preset '" + a.preset + "'");
  if (!sim::parseNoiseLevel(a.noise, &o.noise)) throw Error("--noise: unknown noise level '" + a.noise + "'");
  o.seed = a.seed;
  o.mapping_frames = a.mapping_frames;
  o.query_frames = a.query_frames;
  const sim::SimulationSummary s = sim::writeSimulation(a.out, o);
  if (console.quiet) return;
  std::printf("wrote %s: %d objects, %d mapping frames, %d query frames (%d detections), %zu files\n", a.out.c_str(),
              s.objects, s.mapping_frames, s.query_frames, s.query_detections, s.files.size());
  for (const char* f : {"camera.yaml", "map_groundtruth.json", "map_perturbed.json", "mapping/associations.txt",
                        "mapping/trajectory.txt", "mapping/detections.json", "query/detections.json",
                        "query/groundtruth.txt", "query/ellipse_truth.json"})
    std::printf("  %s/%s\n", a.out.c_str(), f);
}

}  // namespace ellreloc::cli
