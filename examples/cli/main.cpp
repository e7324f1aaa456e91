// The `ellreloc` command: simulate, observe, map, relocalize, evaluate, demo.
// Exit codes: 0 success, 2 bad usage or bad input (one line on stderr), 1 anything else.

#include <CLI/CLI.hpp>
#include <cstdio>

#include "commands.hpp"
#include "ellreloc/error.hpp"

using namespace ellreloc::cli;

int main(int argc, char** argv) {
  CLI::App app("ellreloc: object-based camera relocalization with ellipses and ellipsoids", "ellreloc");
  app.require_subcommand(1);
  Console console;
  app.add_flag("-q,--quiet", console.quiet, "print nothing but results and errors");
  app.footer("Run `ellreloc SUBCOMMAND --help` for a subcommand's options and an example.");

  SimulateArgs sim;
  auto* s = app.add_subcommand("simulate", "write a synthetic scene in the TUM layout (docs/simulator.md)");
  s->add_option("--preset", sim.preset, "office, cluttered or sparse")->capture_default_str();
  s->add_option("--seed", sim.seed, "same seed, same files")->capture_default_str();
  s->add_option("--noise", sim.noise, "none, realistic or hard")->capture_default_str();
  s->add_option("--out", sim.out, "output folder (created)")->required();
  s->add_option("--mapping-frames", sim.mapping_frames)->capture_default_str()->check(CLI::Range(1, 100000));
  s->add_option("--query-frames", sim.query_frames)->capture_default_str()->check(CLI::Range(1, 100000));
  s->footer("Example: ellreloc simulate --preset office --seed 1 --noise realistic --out /tmp/office");

  ObserveArgs obs;
  auto* o = app.add_subcommand("observe", "fill each detection's `ellipse` and `regular` fields");
  o->add_option("--camera", obs.camera, "camera.yaml or .json")->required()->check(CLI::ExistingFile);
  o->add_option("--detections", obs.detections, "detections JSON")->required()->check(CLI::ExistingFile);
  o->add_option("--policy", obs.policy, "paper, bbox or mask (docs/observe.md)")->capture_default_str();
  o->add_option("--out", obs.out, "output detections JSON")->required();
  o->footer("Example: ellreloc observe --camera C.yaml --detections D.json --policy paper --out O.json");

  MapArgs mp;
  auto* m = app.add_subcommand("map", "build an object map from keyframes (docs/mapping.md)");
  m->add_option("--camera", mp.camera)->required()->check(CLI::ExistingFile);
  m->add_option("--associations", mp.associations, "TUM association file (voxel mode: the depth images)")
      ->check(CLI::ExistingFile);
  m->add_option("--trajectory", mp.trajectory, "TUM trajectory of the keyframes (camera->world)")
      ->required()
      ->check(CLI::ExistingFile);
  m->add_option("--detections", mp.detections, "detections with masks (voxel) or boxes")
      ->required()
      ->check(CLI::ExistingFile);
  m->add_option("--mode", mp.mode, "voxel (RGB-D + masks) or boxes (boxes and poses only)")->capture_default_str();
  m->add_option("--out", mp.out, "output map JSON")->required();
  m->footer(
      "Example: ellreloc map --camera S/camera.yaml --associations S/mapping/associations.txt --trajectory "
      "S/mapping/trajectory.txt --detections S/mapping/detections.json --mode voxel --out map.json");

  RelocalizeArgs rl;
  auto* r = app.add_subcommand("relocalize", "recover the camera pose of each frame from its detections");
  r->add_option("--camera", rl.camera)->required()->check(CLI::ExistingFile);
  r->add_option("--map", rl.map, "map JSON or OA-SLAM text map")->required()->check(CLI::ExistingFile);
  r->add_option("--detections", rl.detections)->required()->check(CLI::ExistingFile);
  r->add_option("--method", rl.method, "ours or oa-slam (the OA-SLAM baseline)")->capture_default_str();
  r->add_option("--policy", rl.policy, "observation policy (default: paper for ours, bbox for oa-slam)");
  r->add_option("--out", rl.out, "TUM poses of the relocalized frames")->required();
  r->add_option("--report", rl.report, "per-frame JSON report: status, inliers, score, time");
  auto* points = r->add_option("--points", rl.points,
                               "refine with keypoints matched to the map's points: from this file (same frame "
                               "layout), or from the detections file when no file is given")
                     ->expected(0, 1);
  r->add_option("--threads", rl.threads, "frames in parallel")->capture_default_str()->check(CLI::Range(1, 256));
  auto* camera_up = r->add_option("--camera-up", rl.camera_up,
                                  "gravity prior: the up direction in the camera frame (x right, y down, z forward), "
                                  "for a camera at a fixed tilt, e.g. 0,-1,0 for a level camera")
                        ->expected(3)
                        ->delimiter(',');
  auto* map_up = r->add_option("--map-up", rl.map_up, "gravity prior: the up direction in the map frame, e.g. 0,0,1")
                     ->expected(3)
                     ->delimiter(',');
  camera_up->needs(map_up);
  map_up->needs(camera_up);
  r->add_option("--gravity-sigma", rl.gravity_sigma_deg, "accuracy of the gravity prior in degrees")
      ->capture_default_str()
      ->needs(camera_up);
  r->footer(
      "Example: ellreloc relocalize --camera camera.yaml --map map.json --detections keyframes.detections.json "
      "--method ours --out poses.txt --report report.json --threads 2");

  EvaluateArgs ev;
  auto* e = app.add_subcommand("evaluate", "Table I row: median errors and valid % (FORMATS.md definitions)");
  e->add_option("--groundtruth", ev.groundtruth)->required()->check(CLI::ExistingFile);
  e->add_option("--estimate", ev.estimate)->required()->check(CLI::ExistingFile);
  e->add_option("--detections", ev.detections, "the query frames (default: every ground-truth pose)")
      ->check(CLI::ExistingFile);
  e->add_option("--plot", ev.plot, "PNG: top view and cumulative error curves");
  e->footer("Example: ellreloc evaluate --groundtruth G.txt --estimate poses.txt --detections D.json --plot out.png");

  DemoArgs dm;
  auto* d = app.add_subcommand("demo", "simulate -> map -> relocalize (ours and OA-SLAM) -> evaluate");
  d->add_option("--out", dm.out, "working folder (default: a folder in the system's temp directory)");
  d->add_option("--seed", dm.seed)->capture_default_str();
  d->add_option("--threads", dm.threads)->capture_default_str()->check(CLI::Range(1, 256));
  d->footer("Example: ellreloc demo --out /tmp/ellreloc-demo");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& h) {
    return app.exit(h);
  } catch (const CLI::CallForAllHelp& h) {
    return app.exit(h);
  } catch (const CLI::ParseError& err) {
    if (argc > 1 && argv[1][0] != '-' && app.get_subcommands().empty())
      std::fprintf(stderr, "ellreloc: unknown subcommand '%s' (see --help)\n", argv[1]);
    else
      std::fprintf(stderr, "ellreloc: %s (see --help)\n", err.what());
    return 2;
  }
  try {
    if (s->parsed()) simulate(sim, console);
    if (o->parsed()) observe(obs, console);
    if (m->parsed()) map(mp, console);
    rl.use_points = points->count() > 0;
    if (r->parsed()) relocalize(rl, console);
    if (e->parsed()) printEvaluation(evaluate(ev));
    if (d->parsed()) demo(dm, console);
  } catch (const ellreloc::Error& err) {
    std::fprintf(stderr, "ellreloc: %s\n", err.what());
    return 2;
  } catch (const std::exception& err) {
    std::fprintf(stderr, "ellreloc: internal error: %s\n", err.what());
    return 1;
  }
  return 0;
}
