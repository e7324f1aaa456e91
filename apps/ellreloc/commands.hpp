#pragma once
// The `ellreloc` subcommands, one file each: add<Name>Command registers the options, the plain
// function runs it (so that `demo` can chain them). Each throws ellreloc::Error on bad input
// (main turns it into one line and exit code 2).

#include <string>
#include <vector>

#include "ellreloc/core/evaluation.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/pose/relocalizer_options.hpp"

namespace CLI {
class App;
}

namespace ellreloc::cli {

/// Where progress goes: a bar on a terminal, nothing when quiet.
struct Console {
  bool quiet = false;
  /// A progress bar on stderr, only when stderr is a terminal and not quiet.
  void progress(const char* what, size_t done, size_t total) const;
  void endProgress() const;
};

/// A path given to an option, for messages.
struct NamedPath {
  std::string option, path;
};

/// Before any work: refuses (Error) an output that is the same file as an input or another
/// output (same device and inode, or the same resolved path when it does not exist yet), or
/// that exists and is not a regular file. Empty paths are skipped.
void checkPaths(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs);

struct SimulateArgs {
  std::string preset = "office", noise = "realistic", out;
  unsigned long seed = 1;
  int mapping_frames = 60, query_frames = 100;
};
CLI::App* addSimulateCommand(CLI::App& app, SimulateArgs& a);
void simulate(const SimulateArgs& a, const Console& console);

struct ObserveArgs {
  std::string camera, detections, policy = "paper", out;
};
CLI::App* addObserveCommand(CLI::App& app, ObserveArgs& a);
void observe(const ObserveArgs& a, const Console& console);
/// paper, bbox, mask or given; anything else is an Error naming --policy.
ObservationPolicy parsePolicy(const std::string& name);

struct MapArgs {
  std::string camera, associations, trajectory, detections, mode = "voxel", out;
  int holdout_every = 0;   ///< every N-th frame is left out of the map and measures its quality
  std::string holdout;     ///< detections of frames left out of the map, to measure its quality
  std::vector<double> up;  ///< the world's up direction, when known
};
CLI::App* addMapCommand(CLI::App& app, MapArgs& a);
void map(const MapArgs& a, const Console& console);

struct RelocalizeArgs {
  std::string camera, map, detections, method = "ours", out, report, policy;
  std::string reference;    ///< TUM poses to diagnose each frame against (search or scoring failure)
  std::string envelope;     ///< TUM trajectory of the mapping keyframes: poses outside their envelope are dropped
  bool use_points = false;  ///< refine with the frames' keypoints matched to the map's points
  std::string points;       ///< a file with the keypoints; empty: the detections file's own
  int threads = 1;
  double max_time_ms = 0.0;  ///< wall-clock budget of each frame's search; 0: none
  double min_evidence = AcceptanceOptions().min_evidence;
  bool accept_all = false;
  std::vector<double> camera_up, map_up;  ///< a gravity prior for every frame, when both are given
  double gravity_sigma_deg = 2.0;
};
/// `use_points` is set after parsing, from whether --points was given.
CLI::App* addRelocalizeCommand(CLI::App& app, RelocalizeArgs& a);
/// Returns the number of frames relocalized.
int relocalize(const RelocalizeArgs& a, const Console& console);

struct EvaluateArgs {
  std::string groundtruth, estimate, detections, plot;
};
CLI::App* addEvaluateCommand(CLI::App& app, EvaluateArgs& a);
RelocalizationSummary evaluate(const EvaluateArgs& a);
void printEvaluation(const RelocalizationSummary& e);

struct DemoArgs {
  std::string out;
  unsigned long seed = 1;
  int threads = 2;
};
CLI::App* addDemoCommand(CLI::App& app, DemoArgs& a);
void demo(const DemoArgs& a, const Console& console);

}  // namespace ellreloc::cli
