#pragma once
// The `ellreloc` subcommands as plain functions, so that `demo` can chain them. Each throws
// ellreloc::Error on bad input (main turns it into one line and exit code 2).

#include <string>
#include <vector>

namespace ellreloc::cli {

struct Console {
  bool quiet = false;
  /// A progress bar on stderr, only when stderr is a terminal and not quiet.
  void progress(const char* what, size_t done, size_t total) const;
  void endProgress() const;
};

struct SimulateArgs {
  std::string preset = "office", noise = "realistic", out;
  unsigned long seed = 1;
  int mapping_frames = 60, query_frames = 100;
};
void simulate(const SimulateArgs& a, const Console& console);

struct ObserveArgs {
  std::string camera, detections, policy = "paper", out;
};
void observe(const ObserveArgs& a, const Console& console);

struct MapArgs {
  std::string camera, associations, trajectory, detections, mode = "voxel", out;
};
void map(const MapArgs& a, const Console& console);

struct RelocalizeArgs {
  std::string camera, map, detections, method = "ours", out, report, policy;
  bool use_points = false;  ///< refine with the frames' keypoints matched to the map's points
  std::string points;       ///< a file with the keypoints; empty: the detections file's own
  int threads = 1;
  std::vector<double> camera_up, map_up;  ///< a gravity prior for every frame, when both are given
  double gravity_sigma_deg = 2.0;
};
/// Returns the number of frames relocalized.
int relocalize(const RelocalizeArgs& a, const Console& console);

struct EvaluateArgs {
  std::string groundtruth, estimate, detections, plot;
};
struct Evaluation {
  int frames = 0, relocalized = 0, valid = 0;
  double median_position_cm = 0.0, median_rotation_deg = 0.0;
  double validPercent() const { return frames > 0 ? 100.0 * valid / frames : 0.0; }
};
Evaluation evaluate(const EvaluateArgs& a);
void printEvaluation(const Evaluation& e);

struct DemoArgs {
  std::string out;
  unsigned long seed = 1;
  int threads = 2;
};
void demo(const DemoArgs& a, const Console& console);

}  // namespace ellreloc::cli
